// Float precision that depends neither on where a body is nor on the substep (docs/precision.md):
// each body's positions are kept in its own frame, which follows its centre of mass.
//
// - A 1 m pendulum released at 5 degrees keeps the exact period (4 sqrt(L/g) K(sin(theta0/2))) and
//   loses per period the energy XPBD's implicit step takes from an oscillator of angular
//   frequency w: a factor 1/(1 + w^2 h^2) per substep, (1 + w^2 h^2)^(-T/h) per period.
// - A body translated by 100 m moves and pushes back as it does at the origin.
// - A particle resting on a hard plane reads its weight as lambda/h^2 at any height.

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

using std::numbers::pi;
constexpr double kPendulumG = 9.81;

// The complete elliptic integral of the first kind K(k), by the arithmetic-geometric mean.
double ellipticK(double k) {
  double a = 1.0, b = std::sqrt(1.0 - k * k);
  for (int i = 0; i < 30; ++i) {
    const double next = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = next;
  }
  return pi / (2.0 * a);
}

struct PendulumRun {
  double period;         // mean time between upward zero crossings (s)
  double lossPerPeriod;  // 1 - (E_last / E_first)^(1 / periods)
  double substep;        // h (s)
};

// A kinematic pivot at `pivot` and a 1 kg bob on a hard distance constraint of 1 m, released at
// 5 degrees, 1 iteration per substep; `seconds` of swinging.
PendulumRun swing(int substeps, const Vec3& pivot, double seconds) {
  constexpr double kLength = 1.0, kTheta0 = 5.0 * pi / 180.0;
  SolverSettings s;
  s.timeStep = 1.0 / 60.0;
  s.substeps = substeps;
  s.iterations = 1;
  s.gravity = Vec3(0.0f, -float(kPendulumG), 0.0f);
  s.linearDamping = 0.0f;
  s.timeStages = false;
  s.measureResiduals = false;
  auto model = std::make_shared<BodyModel>();
  model->restPositions = {Vec3::Zero(),
                          Vec3(float(kLength * std::sin(kTheta0)), float(-kLength * std::cos(kTheta0)), 0)};
  model->invMass = {0.0f, 1.0f};
  addDistanceConstraint(*model, 0, 1, 0.0f);
  World w(s);
  w.addBody(model, pivot);

  const Vec3d top = w.position(0);
  const auto energy = [&] {
    const Vec3d bob = w.position(1) - top;
    return 0.5 * w.particles().v[1].cast<double>().squaredNorm() + kPendulumG * (bob.y() + kLength);
  };
  std::vector<double> crossings, energies;
  double t = 0.0, before = (w.position(1) - top).x();
  const double dt = double(s.timeStep);
  for (long k = 0; k < std::lround(seconds / dt); ++k) {
    w.step();
    t += dt;
    const double now = (w.position(1) - top).x();
    if (before < 0.0 && now >= 0.0) {
      crossings.push_back(t - dt * now / (now - before));
      energies.push_back(energy());
    }
    before = now;
  }
  const double periods = double(crossings.size() - 1);
  return {(crossings.back() - crossings.front()) / periods,
          1.0 - std::pow(energies.back() / energies.front(), 1.0 / periods), double(s.timeStep) / substeps};
}

TEST(Precision, APendulumKeepsItsPeriodAndItsImplicitDampingAtAnySubstepAnywhere) {
  const double exact = 4.0 * std::sqrt(1.0 / kPendulumG) * ellipticK(std::sin(5.0 * pi / 360.0));  // 2.00702 s
  const double w2 = kPendulumG;                                                                    // w^2 = g / L
  for (const Vec3& pivot : {Vec3(0, 0, 0), Vec3(100, 100, 100)})
    for (int substeps : {5, 10, 20, 50, 100}) {
      const PendulumRun r = swing(substeps, pivot, 20.0);
      const double h = r.substep, loss = 1.0 - std::pow(1.0 + w2 * h * h, -exact / h);
      EXPECT_NEAR(r.period, exact, 5e-4 * exact) << substeps << " substeps, pivot at " << pivot.transpose();
      EXPECT_NEAR(r.lossPerPeriod, loss, 0.1 * loss) << substeps << " substeps, pivot at " << pivot.transpose();
    }
}

// A jelly on the ground, pressed 10 mm by a fingertip and released, at the origin and 100 m away
// along every axis: the fingertip's goals are the same offsets from the translation (chosen on
// the float grid at 100 m, so that the inputs are the same), and the body must follow the same
// path and push back with the same force for 10 s.
TEST(Precision, ABodyOneHundredMetresAwayMovesAndPushesBackAsAtTheOrigin) {
  struct Trace {
    std::vector<Vec3d> positions;  // every particle every 0.5 s, relative to the translation
    std::vector<double> force;     // the fingertip's vertical force every step (N)
  };
  const auto run = [](const Vec3& at) {
    SolverSettings s;
    s.timeStages = false;
    World w(s);
    Material m;
    m.elastic = ElasticModuli{1e4f, 0.3f, 1000.0f, 0.002f};
    const TetMesh mesh = makeBoxTets(Vec3(-0.05f, 0.0f, -0.05f), Vec3::Constant(0.1f), 4, 4, 4);
    const BodyId body = w.addBody(makeSoftBody(mesh, m), at);
    w.addCollider(Collider::plane(Vec3::UnitY(), at));
    const float grid = std::ldexp(1.0f, -10);  // about 1 mm, on the float grid at 100 m
    const Vec3 above(0.0f, 106 * grid, 0.0f);  // 2 mm above the top, which settles at 92 mm
    const FingertipId tip = w.addFingertip(at + above, 0.01f);
    Trace trace;
    for (int k = 0; k < 600; ++k) {
      const float depth = float(std::min(k, 600 - k) < 120 ? std::min(k, 600 - k) : 120) / 120.0f;  // 2 s in, hold, out
      w.moveFingertip(tip, at + above - Vec3(0.0f, std::round(depth * 12.0f) * grid, 0.0f));
      w.step();
      trace.force.push_back(double(w.fingertipForce(tip).y()));
      if (k % 30 == 29)
        for (Index i = 0; i < w.body(body).particleCount; ++i)
          trace.positions.push_back(w.position(w.particleIndex(body, i)) - at.cast<double>());
    }
    return trace;
  };
  const Trace home = run(Vec3::Zero()), away = run(Vec3::Constant(100.0f));
  double peak = 0.0;
  for (double f : home.force) peak = std::max(peak, std::abs(f));
  ASSERT_GT(peak, 0.1);  // it pressed
  for (std::size_t k = 0; k < home.force.size(); ++k) EXPECT_NEAR(away.force[k], home.force[k], 1e-4 * peak) << k;
  ASSERT_EQ(home.positions.size(), away.positions.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < home.positions.size(); ++k)
    worst = std::max(worst, (away.positions[k] - home.positions[k]).norm());
  EXPECT_LT(worst, 1e-4 * 0.1);  // of the body's size
}

// validation precision note (a): a 5 g particle resting on a hard plane at height Y, 1 kHz x 8
// substeps (h = 125 us): the mean lambda/h^2 over the second second is its weight m g, at
// every Y (in world float coordinates it read 17% high at 1 m and 0 N at 10 m).
TEST(Precision, ARestingParticleReadsItsWeightAtAnyHeight) {
  for (float height : {0.0f, 1.0f, 10.0f, 100.0f, 1000.0f}) {
    SolverSettings s;
    s.timeStep = 1e-3;
    s.substeps = 8;
    s.iterations = 1;
    s.linearDamping = 0.0f;
    s.timeStages = false;
    auto model = std::make_shared<BodyModel>();
    model->restPositions = {Vec3::Zero()};
    model->invMass = {200.0f};
    World w(s);
    const BodyId body = w.addBody(model, Vec3(0.0f, height, 0.0f));
    w.addCollider(Collider::plane(Vec3::UnitY(), Vec3(0.0f, height, 0.0f)));
    double sum = 0.0;
    for (int k = 0; k < 2000; ++k) {
      w.step();
      if (k >= 1000) sum += double(w.particleConstraintForces(body)[0].y());
    }
    EXPECT_NEAR(sum / 1000.0, 0.005 * kPendulumG, 1e-4 * 0.005 * kPendulumG) << "at " << height << " m";
  }
}

}  // namespace
}  // namespace vrd
