// Global shape matching (eqs. 25-28): a rigidly moved body gets no correction; a deformed one is
// pulled back to a rigid copy of its rest shape.

#include <gtest/gtest.h>

#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

// RMS distance of the body's particles from the best rigid copy of its rest shape (eq. 25 at
// its minimum): zero exactly when the body is a rigid motion of its rest shape.
float rigidMismatch(const World& w, BodyId b) {
  const BodyModel& m = *w.body(b).model;
  const ShapeMatchModel& sm = *m.shapeMatching;
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  const Point* p = w.particles().x.data() + w.body(b).firstParticle;
  const ShapeMatchFrame frame = shapeMatchFrame(p, sm, q);
  double sum = 0.0;
  for (std::size_t i = 0; i < m.particleCount(); ++i)
    sum += (p[i].pos - frame.centroid - frame.rotation * sm.restOffsets[i]).squaredNorm();
  return float(std::sqrt(sum / double(m.particleCount())));
}

struct ShapeMatchOnly {
  World world;
  BodyId body;
  std::shared_ptr<const BodyModel> model;

  ShapeMatchOnly(const Vec3& translation, const Quat& rotation) : world(settings()) {
    Material m;
    m.particleMass = 1.0f;  // the energy and the periods below are in unit masses
    m.shapeMatching = {1e-3f, 0.0f};
    model = makeSoftBody(makeBoxTets(Vec3(-0.5f, -0.25f, -0.1f), Vec3(1.0f, 0.5f, 0.2f), 4, 2, 1), m,
                         {false, false, false, true});
    body = world.addBody(model, translation, rotation);
  }
  static SolverSettings settings() {
    SolverSettings s;
    s.gravity.setZero();
    return s;
  }
};

TEST(ShapeMatching, RigidMotionGetsNoCorrection) {
  const Quat rotation(Eigen::AngleAxisf(2.0f, Vec3(1.0f, -2.0f, 0.5f).normalized()));
  ShapeMatchOnly s(Vec3(3.0f, -1.0f, 2.0f), rotation);
  const std::vector<Vec3> start = [&] {
    std::vector<Vec3> v;
    for (const Point& p : s.world.particles().x) v.push_back(p.pos);
    return v;
  }();
  for (int step = 0; step < 10; ++step) s.world.step();
  for (std::size_t i = 0; i < start.size(); ++i) {
    // Float: coordinates ~4 m have an ulp of 4.8e-7, so goals are off by a few ulp; the correction
    // w lambda (1 kg particles) is then at most a few ulp, and ten steps cannot move far.
    EXPECT_LT(s.world.body(s.body).shapeMatchLambda[i].norm(), 2e-6f);
    EXPECT_LT((s.world.particles().x[i].pos - start[i]).norm(), 1e-5f);
  }
}

// Kinetic energy plus the shape-matching energy sum_i m_i/(2 alpha) |x_i - g_i|^2 (unit masses).
double energy(const World& w, BodyId b) {
  const float rms = rigidMismatch(w, b);
  const BodyModel& m = *w.body(b).model;
  double kinetic = 0.0;
  for (Index i = 0; i < m.particleCount(); ++i) kinetic += 0.5 * w.particles().v[w.particleIndex(b, i)].squaredNorm();
  return kinetic + 0.5 / m.shapeMatching->compliance * double(rms) * rms * double(m.particleCount());
}

TEST(ShapeMatching, DeformedBodyIsPulledBackToARigidCopy) {
  ShapeMatchOnly s(Vec3::Zero(), Quat(Eigen::AngleAxisf(0.4f, Vec3::UnitZ())));
  // Stretch it 30% along x and shear it: far from any rigid copy.
  for (Point& p : s.world.particles().x) p.pos = Vec3(1.3f * p.pos.x() + 0.2f * p.pos.y(), p.pos.y(), p.pos.z());
  ASSERT_GT(rigidMismatch(s.world, s.body), 0.05f);
  // The pull is an undamped oscillator (period 2 pi sqrt(alpha m) = 0.2 s) that the implicit
  // (backward Euler) steps damp: its energy may only fall.
  double e = energy(s.world, s.body);
  for (int step = 0; step < 300; ++step) {
    s.world.step();
    const double now = energy(s.world, s.body);
    EXPECT_LE(now, e * (1.0 + 1e-4) + 1e-9) << "step " << step;
    e = now;
  }
  // Per step the amplitude shrinks by 1/sqrt(1 + w^2 h^2) = 0.56 (w h = 1.49): after 5 s, nothing.
  EXPECT_LT(rigidMismatch(s.world, s.body), 1e-4f);
}

// Shape matching's damping acts on the change of C = x - g: a body that falls and turns as a rigid
// whole keeps its goals' motion undamped, so it falls and spins as it does without damping.
TEST(ShapeMatching, DampingLeavesARigidlyMovingBodyAlone) {
  const auto run = [](float damping) {
    SolverSettings settings;
    settings.substeps = 4;
    World world(settings);
    Material m;
    m.particleMass = 1.0f;
    m.shapeMatching = {1e-3f, damping};  // tau = alpha beta
    const BodyId b = world.addBody(makeSoftBody(
        makeBoxTets(Vec3(-0.5f, -0.25f, -0.1f), Vec3(1.0f, 0.5f, 0.2f), 4, 2, 1), m, {false, false, false, true}));
    const Vec3 spin(0.3f, 2.0f, -0.5f);  // rad/s about the centre (0, 0, 0)
    for (Index i = 0; i < world.body(b).particleCount; ++i) {
      const Index k = world.particleIndex(b, i);
      world.particles().v[k] = Vec3(0.2f, 1.0f, 0.0f) + spin.cross(world.particles().x[k].pos);
    }
    for (int step = 0; step < 60; ++step) world.step();
    Vec3d centre = Vec3d::Zero();
    double kinetic = 0.0;
    for (Index i = 0; i < world.body(b).particleCount; ++i) {
      centre += world.position(world.particleIndex(b, i));
      kinetic += 0.5 * world.particles().v[world.particleIndex(b, i)].squaredNorm();
    }
    return std::pair{centre / double(world.body(b).particleCount), kinetic};
  };
  const auto [free, freeKinetic] = run(0.0f);
  const auto [damped, dampedKinetic] = run(10.0f);  // tau 0.01 s: 2.4 times a substep
  // One second of free fall, 4.9 m: the same within float rounding of the positions.
  EXPECT_LT((damped - free).norm(), 1e-5 * free.norm());
  EXPECT_NEAR(dampedKinetic, freeKinetic, 1e-3 * freeKinetic);
}

TEST(ShapeMatching, InvertedBodyRecovers) {
  ShapeMatchOnly s(Vec3::Zero(), Quat::Identity());
  for (Point& p : s.world.particles().x) p.pos.x() = -p.pos.x();  // mirror: det A_pq < 0
  for (int step = 0; step < 120; ++step) s.world.step();
  EXPECT_LT(rigidMismatch(s.world, s.body), 1e-4f);
  EXPECT_GT(s.world.volume(s.body), 0.0);  // oriented the right way round again
}

}  // namespace
}  // namespace vrd
