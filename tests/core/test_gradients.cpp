// Every constraint's analytic gradient against central finite differences, in double precision,
// on random non-degenerate configurations and on the hard cases (near-flat and near-folded
// dihedrals, near-degenerate tets).

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <random>

#include "vrdeform/sim/bend_constraint.h"
#include "vrdeform/sim/collider.h"
#include "vrdeform/sim/contact.h"
#include "vrdeform/sim/distance_constraint.h"
#include "vrdeform/sim/strain_constraint.h"
#include "vrdeform/sim/volume_constraint.h"

namespace vrd {
namespace {

using V = Vec3T<double>;
using M = Mat3T<double>;

// Central difference of f with respect to particle k, coordinate d. Step 1e-6: truncation error
// ~ h^2 |f'''| ~ 1e-12 and rounding ~ 1e-16/h ~ 1e-10 for O(1) inputs.
template <std::size_t N>
V numericGradient(const std::function<double(const std::array<V, N>&)>& f, std::array<V, N> p, std::size_t k,
                  double h = 1e-6) {
  V g;
  for (int d = 0; d < 3; ++d) {
    const double keep = p[k][d];
    p[k][d] = keep + h;
    const double plus = f(p);
    p[k][d] = keep - h;
    const double minus = f(p);
    p[k][d] = keep;
    g[d] = (plus - minus) / (2 * h);
  }
  return g;
}

// |analytic - numeric| <= 1e-6 (|numeric| + 1): far above the FD error, far below any wrong term.
void expectGradientsMatch(const V& analytic, const V& numeric, const std::string& what) {
  EXPECT_LE((analytic - numeric).norm(), 1e-6 * (numeric.norm() + 1.0))
      << what << "\n analytic " << analytic.transpose() << "\n numeric  " << numeric.transpose();
}

V randomPoint(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return V(u(rng), u(rng), u(rng));
}

std::array<V, 4> randomTet(std::mt19937& rng, double minShape = 0.05) {
  for (;;) {
    std::array<V, 4> p{randomPoint(rng), randomPoint(rng), randomPoint(rng), randomPoint(rng)};
    double longest = 0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) longest = std::max(longest, (p[a] - p[b]).norm());
    if (std::abs(6 * signedTetVolume(p[0], p[1], p[2], p[3])) > minShape * std::pow(longest, 3)) return p;
  }
}

TEST(Gradients, Distance) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 100; ++trial) {
    std::array<V, 2> p{randomPoint(rng), randomPoint(rng)};
    const double rest = 0.7;
    const auto e = evalDistance(p[0], p[1], rest);
    std::function<double(const std::array<V, 2>&)> C = [&](const auto& q) { return evalDistance(q[0], q[1], rest).C; };
    expectGradientsMatch(e.n, numericGradient(C, p, 0), "p1");
    expectGradientsMatch(-e.n, numericGradient(C, p, 1), "p2");
  }
}

void checkVolume(const std::array<V, 4>& p, const std::string& what) {
  const auto e = evalVolume(p[0], p[1], p[2], p[3], 0.1);
  std::function<double(const std::array<V, 4>&)> C = [](const auto& q) {
    return evalVolume(q[0], q[1], q[2], q[3], 0.1).C;
  };
  for (std::size_t k = 0; k < 4; ++k) expectGradientsMatch(e.grad[k], numericGradient(C, p, k), what);
}

TEST(Gradients, Volume) {
  std::mt19937 rng(2);
  for (int trial = 0; trial < 100; ++trial) checkVolume(randomTet(rng), "random tet");
  // Near-degenerate (almost flat) and inverted tets: the gradient is the face area vector, still exact.
  for (int trial = 0; trial < 50; ++trial) {
    auto p = randomTet(rng);
    p[3] = (p[0] + p[1] + p[2]) / 3.0 + 1e-4 * randomPoint(rng);
    checkVolume(p, "near-flat tet");
    std::swap(p[1], p[2]);
    checkVolume(p, "inverted tet");
  }
}

void checkStrain(const std::array<V, 4>& rest, const std::array<V, 4>& p, const std::string& what) {
  M restShape;
  restShape << rest[1] - rest[0], rest[2] - rest[0], rest[3] - rest[0];
  const M invRest = restShape.inverse();
  for (int c = 0; c < kStrainComponents; ++c) {
    const auto e = evalStrainComponent(p[0], p[1], p[2], p[3], invRest, c);
    std::function<double(const std::array<V, 4>&)> C = [&](const auto& q) {
      const M F = deformationGradient(q[0], q[1], q[2], q[3], invRest);
      const M S = F.transpose() * F;  // eqs. 32-34 straight from the definition
      const int i = kStrainAxes[c][0], j = kStrainAxes[c][1];
      return S(i, j) - (i == j ? 1.0 : 0.0);
    };
    EXPECT_NEAR(e.C, C(p), 1e-12);
    for (std::size_t k = 0; k < 4; ++k)
      expectGradientsMatch(e.grad[k], numericGradient(C, p, k), what + " component " + std::to_string(c));
  }
}

TEST(Gradients, Strain) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 50; ++trial) checkStrain(randomTet(rng), randomTet(rng), "random");
  for (int trial = 0; trial < 20; ++trial) {
    const auto rest = randomTet(rng, 0.01);  // thin rest tets: large D_rest^-1
    auto p = rest;
    p[3] = (p[0] + p[1] + p[2]) / 3.0 + 1e-4 * randomPoint(rng);  // squashed almost flat
    checkStrain(rest, p, "near-degenerate");
  }
}

// A hinge: shared edge p1-p2 on the x axis, wings at angle `theta` apart from flat.
std::array<V, 4> hinge(double theta, std::mt19937& rng, double jitter = 0.05) {
  std::array<V, 4> p{V(0, 0, 0), V(1, 0, 0), V(0.4, 1, 0), V(0.6, -std::cos(theta), std::sin(theta))};
  for (auto& q : p) q += jitter * randomPoint(rng);
  return p;
}

void checkBend(const std::array<V, 4>& p, const std::string& what) {
  const double rest = 0.3;
  const auto e = evalBend(p[0], p[1], p[2], p[3], rest);
  ASSERT_FALSE(e.grad[0].isZero()) << what;
  std::function<double(const std::array<V, 4>&)> theta = [&](const auto& q) {
    return evalBend(q[0], q[1], q[2], q[3], rest).theta;
  };
  for (std::size_t k = 0; k < 4; ++k) expectGradientsMatch(e.grad[k], numericGradient(theta, p, k), what);
}

TEST(Gradients, BendRandom) {
  std::mt19937 rng(4);
  for (int trial = 0; trial < 100; ++trial) {
    const auto p = randomTet(rng);  // any four points in general position form a hinge
    checkBend(p, "random");
  }
}

TEST(Gradients, BendNearFlatAndNearFolded) {
  std::mt19937 rng(5);
  for (double theta : {0.0, 1e-6, -1e-6, 1e-3, -1e-3})
    checkBend(hinge(theta, rng, 0.0), "flat " + std::to_string(theta));
  for (double theta : {3.1, -3.1, 3.14, -3.14}) checkBend(hinge(theta, rng, 0.0), "folded " + std::to_string(theta));
  for (int trial = 0; trial < 50; ++trial) checkBend(hinge(1e-4 * (trial - 25), rng), "jittered near flat");
}

TEST(Gradients, BendAngleMatchesEq24) {
  // Eq. 24 measures arccos(n1.n2) with n1 = (p2-p1)x(p3-p1), n2 = (p2-p1)x(p4-p1): pi - |theta|.
  std::mt19937 rng(6);
  for (int trial = 0; trial < 100; ++trial) {
    const auto p = randomTet(rng);
    const V n1 = (p[1] - p[0]).cross(p[2] - p[0]).normalized(), n2 = (p[1] - p[0]).cross(p[3] - p[0]).normalized();
    const double eq24 = std::acos(std::clamp(n1.dot(n2), -1.0, 1.0));
    EXPECT_NEAR(std::numbers::pi - std::abs(evalBend(p[0], p[1], p[2], p[3], 0.0).theta), eq24, 1e-9);
  }
}

TEST(Gradients, BendDegenerateTriangleIsInactive) {
  const V a(0, 0, 0), b(1, 0, 0), onEdge(0.5, 0, 0), c(0.5, 1, 0);
  const auto e = evalBend(a, b, onEdge, c, 0.0);
  for (const auto& g : e.grad) EXPECT_TRUE(g.isZero());
}

TEST(Gradients, FingertipContact) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 100; ++trial) {
    std::array<V, 2> p{randomPoint(rng), randomPoint(rng)};  // particle, sphere centre
    const auto e = evalSphereContact(p[0], p[1], 0.3);
    std::function<double(const std::array<V, 2>&)> C = [](const auto& q) {
      return evalSphereContact(q[0], q[1], 0.3).C;
    };
    expectGradientsMatch(e.n, numericGradient(C, p, 0), "fingertip contact");
  }
}

// Distance from p to triangle (a, b, c) the plain way, independent of the Voronoi-region walk under
// test: the projection onto the plane when it falls inside all three edges, else the nearest edge.
double referenceTriangleDistance(const V& p, const V& a, const V& b, const V& c) {
  const V n = (b - a).cross(c - a);
  if ((b - a).cross(p - a).dot(n) >= 0 && (c - b).cross(p - b).dot(n) >= 0 && (a - c).cross(p - c).dot(n) >= 0)
    return std::abs((p - a).dot(n)) / n.norm();
  auto segment = [&](const V& s, const V& e) {
    const double t = std::clamp((p - s).dot(e - s) / (e - s).squaredNorm(), 0.0, 1.0);
    return (p - s - t * (e - s)).norm();
  };
  return std::min({segment(a, b), segment(b, c), segment(c, a)});
}

std::array<V, 3> randomTriangle(std::mt19937& rng) {
  for (;;) {
    const std::array<V, 3> t{randomPoint(rng), randomPoint(rng), randomPoint(rng)};
    const double longest =
        std::max({(t[1] - t[0]).squaredNorm(), (t[2] - t[1]).squaredNorm(), (t[0] - t[2]).squaredNorm()});
    if ((t[1] - t[0]).cross(t[2] - t[0]).norm() > 0.1 * longest) return t;
  }
}

// The sphere against a triangle: C = |c - q| - r with grad_{x_k} C = -b_k n and grad_c C = n. The
// distance to a convex set is differentiable off the set, across the Voronoi regions too, so the
// finite differences apply with the centre in the face, edge or vertex region (checked by how many
// barycentric weights vanish; -1: any region).
TEST(Gradients, FingertipTriangleContact) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double r = 0.3;
  std::function<double(const std::array<V, 4>&)> C = [&](const auto& q) {
    return evalFingertipTriangleContact(q[0], q[1], q[2], q[3], r).C;
  };
  auto check = [&](const std::array<V, 4>& p, int zeroWeights, const std::string& what) {
    const auto e = evalFingertipTriangleContact(p[0], p[1], p[2], p[3], r);
    ASSERT_NEAR(e.n.norm(), 1.0, 1e-12) << what;
    EXPECT_NEAR(e.C + r, referenceTriangleDistance(p[3], p[0], p[1], p[2]), 1e-12) << what;
    EXPECT_NEAR(e.b[0] + e.b[1] + e.b[2], 1.0, 1e-12) << what;
    int zeros = 0;
    for (double b : e.b) {
      EXPECT_GE(b, 0.0) << what;
      zeros += b == 0.0;
    }
    if (zeroWeights >= 0) {
      EXPECT_EQ(zeros, zeroWeights) << what;
    }
    for (std::size_t k = 0; k < 3; ++k)
      expectGradientsMatch(-e.b[k] * e.n, numericGradient(C, p, k), what + ", corner " + std::to_string(k));
    expectGradientsMatch(e.n, numericGradient(C, p, 3), what + ", centre");
  };
  for (int trial = 0; trial < 100; ++trial) {
    const auto t = randomTriangle(rng);
    check({t[0], t[1], t[2], 1.5 * randomPoint(rng)}, -1, "random centre");
  }
  for (int trial = 0; trial < 50; ++trial) {
    const auto t = randomTriangle(rng);
    const V normal = (t[1] - t[0]).cross(t[2] - t[0]).normalized();
    const double side = (u(rng) < 0.5 ? -1.0 : 1.0) * (0.05 + u(rng));  // either side of the face
    // Face: a point inside (weights >= 0.05) lifted off the plane.
    V b(0.05 + u(rng), 0.05 + u(rng), 0.05 + u(rng));
    b /= b.sum();
    check({t[0], t[1], t[2], b[0] * t[0] + b[1] * t[1] + b[2] * t[2] + side * normal}, 0, "face region");
    // Edge k -> k+1: a point of the edge moved away from the opposite corner in the plane, and off it.
    for (int k = 0; k < 3; ++k) {
      const V& s = t[k];
      const V& e = t[(k + 1) % 3];
      const V& opposite = t[(k + 2) % 3];
      V away = (e - s).cross(normal).normalized();
      if (away.dot(opposite - s) > 0) away = -away;
      const V onEdge = s + (0.1 + 0.8 * u(rng)) * (e - s);
      check({t[0], t[1], t[2], onEdge + (0.05 + u(rng)) * away + 0.5 * side * normal}, 1,
            "edge region " + std::to_string(k));
    }
    // Vertex k: beyond the corner, against both of its edges.
    for (int k = 0; k < 3; ++k) {
      const V& corner = t[k];
      const V out = -((t[(k + 1) % 3] - corner).normalized() + (t[(k + 2) % 3] - corner).normalized());
      check({t[0], t[1], t[2], corner + (0.05 + u(rng)) * out + 0.5 * side * normal}, 2,
            "vertex region " + std::to_string(k));
    }
  }
}

TEST(Gradients, FingertipTriangleContactOnTheTriangleAndDegenerate) {
  // The centre on the face: no direction from c - q, so the triangle's (outward) unit normal.
  const V a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const auto on = evalFingertipTriangleContact(a, b, c, V(0.25, 0.25, 0.0), 0.1);
  EXPECT_NEAR(on.C, -0.1, 1e-15);
  EXPECT_TRUE(on.n.isApprox(V(0, 0, 1)));
  const auto onEdge = evalFingertipTriangleContact(a, b, c, V(0.5, 0.0, 0.0), 0.1);
  EXPECT_TRUE(onEdge.n.isApprox(V(0, 0, 1)));
  // Zero area (a corner on the opposite edge, or two corners coincident): no contact.
  for (const auto& e : {evalFingertipTriangleContact(a, b, V(0.5, 0, 0), V(0.5, 0.05, 0.0), 0.1),
                        evalFingertipTriangleContact(a, a, c, V(0.0, 0.5, 0.05), 0.1)}) {
    EXPECT_TRUE(e.n.isZero());
    EXPECT_EQ(e.b[0] + e.b[1] + e.b[2], 0.0);
  }
}

TEST(Gradients, ColliderSignedDistance) {
  std::mt19937 rng(8);
  const Mat3 rotation = Eigen::AngleAxisf(0.7f, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Collider colliders[] = {Collider::plane(Vec3(0.3f, 1.0f, -0.2f), Vec3(0.1f, -0.2f, 0.0f)),
                                Collider::sphere(Vec3(0.1f, 0.2f, -0.1f), 0.6f),
                                Collider::box(Vec3(0.0f, 0.1f, 0.0f), Vec3(0.5f, 0.3f, 0.4f), rotation)};
  for (const Collider& c : colliders)
    for (int trial = 0; trial < 200; ++trial) {
      const Vec3 p = (1.5 * randomPoint(rng)).cast<float>();
      const SurfacePoint s = closestSurface(c, p);
      EXPECT_NEAR(s.normal.norm(), 1.0f, 1e-5f);
      // The distance changes at rate 1 along the normal (float: FD step 1e-3, tolerance 1e-2).
      const float h = 1e-3f;
      const float slope =
          (closestSurface(c, p + h * s.normal).distance - closestSurface(c, p - h * s.normal).distance) / (2 * h);
      EXPECT_NEAR(slope, 1.0f, 1e-2f) << "shape " << int(c.shape) << " at " << p.transpose();
    }
}

}  // namespace
}  // namespace vrd
