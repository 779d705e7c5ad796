// V8 (docs/validation.md): momentum of a free-floating soft body (g = 0, no contacts) with all internal
// constraints active. Every XPBD correction is dp_i = w_i grad_i C dlambda and the constraint
// functions are translation and rotation invariant, so sum_i m_i dp_i = 0 and
// sum_i m_i p_i x dp_i = 0 for each projection (RB20 section 3.3): internal constraints do not
// change the linear momentum, and they exert no net torque.
//
// Two effects that are not leaks set the tolerances; both are derived below.
//
// 1. Float32 positions (P7). Every position update p += dp rounds to the float grid, spacing
//    ulp(|x|), and v = (p - x)/h keeps the error, so a particle's momentum moves by up to
//    ~m ulp/h per substep; a correction smaller than ulp/2 is lost altogether. A rotating body
//    needs centripetal corrections w^2 r h^2 per substep (1.25e-8 m for w = 0.3 rad/s, h = 1/600 s:
//    below ulp(0.5 m)/2), so these errors are not random: they are partly systematic. The scale
//    of the error is one ulp per particle per substep,
//        |dP| <= T sum_i m_i ulp(|x|max) / h^2     over a time T with substep h,
//    which for 1 kg at |x| < 0.125 m (ulp 7.5e-9 m), h = 1/60 s, T = 1 s and P = 0.1 kg m/s is
//    2.7e-4 relative: 1e-6 per second is out of reach in float32 (it would need
//    ulp/(h^2 V) < 1e-6, i.e. h > 0.27 s at these scales, or a much larger body speed, which
//    carries the body away from the origin and grows ulp in proportion). With 10 substeps the
//    bound is 100 times larger (measured drifts grow accordingly: ~1e-3 per second), so these
//    tests use one substep and keep the body near the origin. The drift is rounding and not a
//    leak: moving the same spinning body 0.5 m or 4 m away from the origin raises it by one and
//    two orders of magnitude, growing with ulp(|x|), which a translation-invariant leak could not. A
//    genuine leak, e.g. corrections not weighted by inverse mass, would move P by a fraction f of
//    the corrections, ~f w^2 R/V = 0.5 f per second here: the bound still catches f > 1e-3.
// 2. The integrator. XPBD is backward Euler in positions, which damps rotation: a rigid rotation
//    by theta per step is followed by a predicted position 2x^n - x^{n-1} whose best rigid fit turns
//    by atan(sin theta / (2 - cos theta)) = theta - theta^3 + ..., so the spin decays at the rate
//    w^2 h (relative, per second) even with exact arithmetic and converged constraints. The
//    tests compare L with this exact discrete rigid-body recurrence (rigidSpinRatio) instead of
//    with L0, to 1e-4 per second (the V8 tolerance), with w h = 1/60 (decay 1.6e-2 in 1 s).
//    For L the same one-ulp-per-particle worst case, T sum m r ulp/h^2 / (I w), is 7e-4, but the
//    rounding errors of different particles mostly cancel in the torque: the volume + strain body
//    stays within 3e-5 of the recurrence, so the V8 tolerance is kept.
//
// Shape matching uses a stiff compliance here (1e-3 per unit mass, w = 32 rad/s) so that its
// corrections matter; with the default 0.3 they are ~1e3 times weaker and its momentum balance
// would hardly be tested.

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <ostream>
#include <string>

#include "test_support.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

using testing::record;

using Vd = Vec3T<double>;

struct Momenta {
  double mass = 0;
  Vd com = Vd::Zero(), P = Vd::Zero(), L = Vd::Zero();  // L about the centre of mass
  double maxCoordinate = 0;                             // max |x| component (m)
};

Momenta momenta(const World& world, BodyId id) {
  const Body& body = world.body(id);
  const Particles& q = world.particles();
  Momenta m;
  for (Index i = body.firstParticle; i < body.firstParticle + body.particleCount; ++i) {
    const double mi = 1.0 / q.x[i].w;
    m.mass += mi;
    m.com += mi * q.x[i].pos.cast<double>();
    m.P += mi * q.v[i].cast<double>();
    m.maxCoordinate = std::max(m.maxCoordinate, double(q.x[i].pos.cwiseAbs().maxCoeff()));
  }
  m.com /= m.mass;
  for (Index i = body.firstParticle; i < body.firstParticle + body.particleCount; ++i)
    m.L += (1.0 / q.x[i].w) * (q.x[i].pos.cast<double>() - m.com).cross(q.v[i].cast<double>());
  return m;
}

// Backward Euler (XPBD, converged) for a rigid body spinning about a principal axis: the first step
// turns by atan(keep w h) from the tangential start velocity; afterwards the damped chord velocity
// keep * (x^n - x^{n-1})/h predicts x^n + h v, whose rigid fit turns by
// atan2(keep sin t, 1 + keep (1 - cos t)). L_n/L_0 = sin(t_n)/(w h). keep = 1 - c h is the
// per-substep linear damping factor.
double rigidSpinRatio(double omega, double h, double keep, long substeps) {
  const double t0 = omega * h;
  double t = std::atan(keep * t0);
  for (long n = 1; n < substeps; ++n) t = std::atan2(keep * std::sin(t), 1.0 + keep * (1.0 - std::cos(t)));
  return std::sin(t) / t0;
}

double ulp(double x) {
  const float f = float(x);
  return double(std::nextafter(f, std::numeric_limits<float>::infinity()) - f);
}

struct Variant {
  const char* name;
  ConstraintSet constraints;
};
void PrintTo(const Variant& v, std::ostream* os) { *os << v.name; }

constexpr float kSize = 0.1f;              // cube edge (m); 3x3x3 cells, 64 particles, 1 kg
constexpr float kSpin = 1.0f;              // rad/s about the major principal axis
constexpr float kSpeed = 0.1f;             // m/s: the body crosses the origin, |x| < 0.2 m throughout
constexpr float kShapeCompliance = 1e-3f;  // stiff enough (w = 1/sqrt(alpha) = 32 rad/s) to matter

struct SpinRun {
  Momenta start, end;
  double h = 0, T = 0;
  long substeps = 0;
  double maxCoordinate = 0;
  double keep = 1;
};

SpinRun simulate(const ConstraintSet& constraints, float linearDamping, double seconds = 1.0) {
  Material material;
  material.elastic = ElasticModuli{1e4f, 0.3f, 1000.0f};  // no Rayleigh damping by default
  material.shapeMatching = {kShapeCompliance, 0.0f};      // undamped
  const Vd direction = Vd(1.0, 0.5, -0.3).normalized();
  // Start half a flight behind the origin so that |x| stays small (P7).
  const Vec3 start = (-0.5 * seconds * kSpeed * direction).cast<float>() - Vec3::Constant(0.5f * kSize);
  const auto model = makeSoftBody(makeBoxTets(start, Vec3::Constant(kSize), 3, 3, 3), material, constraints);

  SolverSettings settings;
  settings.timeStep = 1.0f / 60.0f;
  settings.substeps = 1;
  settings.iterations = 5;  // the paper's count
  settings.gravity = Vec3::Zero();
  settings.linearDamping = linearDamping;
  World world(settings);
  const BodyId body = world.addBody(model);

  // Spin about the principal axis of largest inertia (stable; the rigid recurrence assumes a
  // principal axis), plus a translation.
  const Momenta rest = momenta(world, body);
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  for (Index i = 0; i < model->particleCount(); ++i) {
    const Point& x = world.particles().x[world.particleIndex(body, i)];
    const Vd r = x.pos.cast<double>() - rest.com;
    inertia += (1.0 / x.w) * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
  }
  const Vd axis = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inertia).eigenvectors().col(2);
  for (Index i = 0; i < model->particleCount(); ++i) {
    const Index g = world.particleIndex(body, i);
    const Vd r = world.particles().x[g].pos.cast<double>() - rest.com;
    world.particles().v[g] = (kSpeed * direction + kSpin * axis.cross(r)).cast<float>();
  }

  SpinRun run;
  run.start = momenta(world, body);
  run.h = settings.substepSize();
  const int steps = int(std::lround(seconds / settings.timeStep));
  run.substeps = long(steps) * settings.substeps;
  run.T = steps * double(settings.timeStep);
  run.keep = std::max(0.0, 1.0 - double(linearDamping) * run.h);
  run.maxCoordinate = run.start.maxCoordinate;
  for (int k = 0; k < steps; ++k) {
    world.step();
    run.maxCoordinate = std::max(run.maxCoordinate, momenta(world, body).maxCoordinate);
  }
  run.end = momenta(world, body);
  EXPECT_TRUE(world.takeEvents().empty());
  return run;
}

// The float32 bound of the header: one ulp of the largest coordinate per particle per substep.
double floatMomentumBound(const SpinRun& r) { return r.T * r.start.mass * ulp(r.maxCoordinate) / (r.h * r.h); }

class Momentum : public ::testing::TestWithParam<Variant> {};

TEST_P(Momentum, LinearMomentumConstant) {
  const SpinRun r = simulate(GetParam().constraints, 0.0f);
  const double bound = floatMomentumBound(r);
  ASSERT_LT(bound, 1e-3 * r.start.P.norm());  // the bound is tight enough to mean something
  record("P_drift_rel_per_s", (r.end.P - r.start.P).norm() / r.start.P.norm() / r.T);
  record("float_bound_rel_per_s", bound / r.start.P.norm() / r.T);
  EXPECT_LT((r.end.P - r.start.P).norm(), bound)
      << "relative drift " << (r.end.P - r.start.P).norm() / r.start.P.norm() / r.T << " per second; float32 bound "
      << bound / r.start.P.norm() / r.T;
}

// Note: the shape-matching variants fail at the time of writing (|L| about 9e-4 below the
// recurrence after 1 s): extractRotation (math/rotation.h) stops once its step is below 1e-6 rad,
// warm-started from the last R, so R trails the spinning body and the goals g_i = c + R q_i pull
// it back, a torque of about -I delta / (alpha + h^2) per projection. With the stop at 1e-7 rad
// (or 1e-9) these tests pass.
TEST_P(Momentum, AngularMomentumConstant) {
  const SpinRun r = simulate(GetParam().constraints, 0.0f);
  const double expected = rigidSpinRatio(kSpin, r.h, 1.0, r.substeps);  // ~0.984: backward Euler's own decay
  const double L0 = r.start.L.norm();
  const double measured = r.end.L.dot(r.start.L) / (L0 * L0);  // component along the initial L
  record("L_ratio", measured);
  record("L_ratio_expected", expected);
  record("L_direction_change", (r.end.L.normalized() - r.start.L.normalized()).norm());
  EXPECT_NEAR(measured, expected, 1e-4 * r.T) << "|L|/|L0| beyond the integrator's spin decay";
  // The direction of L must not turn either (no spurious torque across the axis).
  EXPECT_LT((r.end.L.normalized() - r.start.L.normalized()).norm(), 1e-4 * r.T);
}

// With linear damping c every velocity is scaled by keep = 1 - c h per substep before the
// constraints, which conserve momentum: P(t) = keep^n P0 exactly (an exponential, not a drift).
TEST_P(Momentum, LinearDampingDecaysExponentially) {
  const float c = 3.0f;  // 1/s: P falls to 0.95^60 = 4.6% in 1 s
  const SpinRun r = simulate(GetParam().constraints, c);
  const double keepN = std::pow(r.keep, double(r.substeps));
  record("P_ratio", r.end.P.dot(r.start.P) / r.start.P.squaredNorm());
  record("P_ratio_expected", keepN);
  record("P_error_rel", (r.end.P - keepN * r.start.P).norm() / r.start.P.norm());
  EXPECT_LT((r.end.P - keepN * r.start.P).norm(), floatMomentumBound(r))
      << "P/P0 = " << r.end.P.norm() / r.start.P.norm() << ", expected " << keepN;
  // Angular momentum: the damped rigid recurrence (keep^n times a slightly smaller spin decay).
  const double L0 = r.start.L.norm();
  record("L_ratio", r.end.L.dot(r.start.L) / (L0 * L0));
  record("L_ratio_expected", rigidSpinRatio(kSpin, r.h, r.keep, r.substeps));
  EXPECT_NEAR(r.end.L.dot(r.start.L) / (L0 * L0), rigidSpinRatio(kSpin, r.h, r.keep, r.substeps), 1e-4 * r.T);
}

INSTANTIATE_TEST_SUITE_P(Momentum, Momentum,
                         ::testing::Values(Variant{"VolumeStrain", ConstraintSet{false, true, true, false}},
                                           Variant{"VolumeStrainShapeMatching", ConstraintSet{false, true, true, true}},
                                           Variant{"EdgesVolumeStrainShapeMatching",
                                                   ConstraintSet{true, true, true, true}}),
                         [](const ::testing::TestParamInfo<Variant>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace vrd
