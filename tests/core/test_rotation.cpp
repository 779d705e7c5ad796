// Rotation extraction (Müller et al. 2016) on well-conditioned, degenerate and inverted input.

#include <gtest/gtest.h>

#include <random>

#include "vrdeform/math/rotation.h"

namespace vrd {
namespace {

using Md = Mat3T<double>;
using Qd = Eigen::Quaterniond;

Qd randomRotation(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return Qd(n(rng), n(rng), n(rng), n(rng)).normalized();
}

void expectProperRotation(const Md& R) {
  EXPECT_TRUE(R.allFinite());
  EXPECT_LT((R.transpose() * R - Md::Identity()).norm(), 1e-9);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-9);
}

TEST(Rotation, RecoversRotationOfStretchedMatrix) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> stretch(0.5, 2.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Md R = randomRotation(rng).toRotationMatrix();
    const Md Q = randomRotation(rng).toRotationMatrix();
    const Md S = Q * Eigen::Vector3d(stretch(rng), stretch(rng), stretch(rng)).asDiagonal() * Q.transpose();  // SPD
    Qd q = Qd::Identity();
    extractRotation<double>(R * S, q, 100);
    EXPECT_LT((q.toRotationMatrix() - R).norm(), 1e-8) << "trial " << trial;
  }
}

TEST(Rotation, WarmStartConvergesFasterThanColdStart) {
  std::mt19937 rng(12);
  for (int trial = 0; trial < 20; ++trial) {
    const Qd truth = randomRotation(rng);
    const Md A = truth.toRotationMatrix() * Eigen::Vector3d(1.2, 0.9, 1.05).asDiagonal();
    const Qd coldStart = Qd::Identity();
    const Qd warmStart =
        truth * Qd(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()));  // last frame's answer, a bit off
    Qd cold = coldStart, warm = warmStart;
    EXPECT_LT(extractRotation<double>(A, warm, 200), 200);
    extractRotation<double>(A, cold, 200);
    EXPECT_LT(warm.angularDistance(truth), 1e-8);
    EXPECT_LT(cold.angularDistance(truth), 1e-8);
    // Closer after the same few steps. (Counting the steps to the 1e-12 tolerance would compare
    // rounding noise near that floor, which differs between CPUs.)
    if (truth.angularDistance(Qd::Identity()) > 0.5) {
      Qd coldFew = coldStart, warmFew = warmStart;
      extractRotation<double>(A, coldFew, 5);
      extractRotation<double>(A, warmFew, 5);
      EXPECT_LT(warmFew.angularDistance(truth), coldFew.angularDistance(truth)) << "trial " << trial;
    }
  }
}

TEST(Rotation, DegenerateAndInvertedInputGiveProperRotations) {
  std::mt19937 rng(13);
  for (int trial = 0; trial < 100; ++trial) {
    const Md R = randomRotation(rng).toRotationMatrix();
    const Md cases[] = {
        R * Eigen::Vector3d(1.0, 1.0, 0.0).asDiagonal(),     // flattened to a plane
        R * Eigen::Vector3d(1.0, 0.0, 0.0).asDiagonal(),     // collapsed to a line
        R * Eigen::Vector3d(1.0, 1.0, -1.0).asDiagonal(),    // mirrored (det < 0)
        R * Eigen::Vector3d(-1.0, -1.0, -1.0).asDiagonal(),  // point reflection
        Md::Zero(),
    };
    for (const Md& A : cases) {
      Qd q = randomRotation(rng);
      extractRotation<double>(A, q, 100);
      expectProperRotation(q.toRotationMatrix());
    }
    // A flattened rotation keeps the in-plane part: the result maps the surviving axes exactly.
    Qd q = Qd::Identity();
    extractRotation<double>(R * Eigen::Vector3d(1.0, 1.0, 0.0).asDiagonal(), q, 200);
    EXPECT_LT((q.toRotationMatrix().leftCols<2>() - R.leftCols<2>()).norm(), 1e-6);
  }
}

TEST(Rotation, FloatMatchesDouble) {
  std::mt19937 rng(14);
  for (int trial = 0; trial < 50; ++trial) {
    const Md A = randomRotation(rng).toRotationMatrix() * Eigen::Vector3d(1.3, 0.8, 1.1).asDiagonal();
    Qd qd = Qd::Identity();
    Quat qf = Quat::Identity();
    extractRotation<double>(A, qd, 100);
    extractRotation<float>(A.cast<float>(), qf, 100);
    EXPECT_LT((qf.toRotationMatrix().cast<double>() - qd.toRotationMatrix()).norm(), 1e-5);
  }
}

}  // namespace
}  // namespace vrd
