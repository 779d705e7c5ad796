// Contact between bodies and of a body with itself (sim/body_contact.h), checked with figures from
// mechanics and geometry: a stack's weight carried through the contact, momentum through a
// collision, surfaces that never cross (the mesh pipeline's own intersection check), no tunnelling.

#include <gtest/gtest.h>

#include <cmath>

#include "test_support.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/mesh/surface_check.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

using testing::kG;

std::shared_ptr<const BodyModel> block(const Vec3& size, int nx, int ny, int nz, float youngs,
                                       float density = 1000.0f) {
  Material m;
  m.elastic = ElasticModuli{youngs, 0.3f, density};
  return makeSoftBody(makeBoxTets(Vec3::Zero(), size, nx, ny, nz), m, {false, true, true, false});
}

double mass(const World& w, BodyId id) {
  double sum = 0.0;
  const Body& b = w.body(id);
  for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i)
    if (w.particles().x[i].w > 0.0f) sum += 1.0 / w.particles().x[i].w;
  return sum;
}

// The bodies' surfaces where they are, as one mesh: two closed surfaces that do not cross have no
// intersecting face pair, and neither does a surface that does not cross itself.
TriMesh surfaces(const World& w, std::initializer_list<BodyId> ids) {
  TriMesh out;
  for (BodyId id : ids) {
    const Body& b = w.body(id);
    const Index first = Index(out.vertices.size());
    for (Index i = 0; i < b.particleCount; ++i) out.vertices.push_back(w.particles().x[b.firstParticle + i].pos);
    for (Triangle t : b.model->surface) out.triangles.push_back({t[0] + first, t[1] + first, t[2] + first});
  }
  return out;
}

// 8 substeps x 10 iterations, warm-started and damped: what the stacking tests settle with.
SolverSettings restingSettings() {
  SolverSettings s;
  s.substeps = 8;
  s.iterations = 10;
  s.linearDamping = 5.0f;
  s.warmStart = true;
  return s;
}

bool crossing(const TriMesh& mesh) {
  SurfaceCheckOptions o;
  o.requireClosed = false;
  return checkSurface(mesh, o).find(SurfaceDefect::SelfIntersection) != nullptr;
}

// A 10 cm block on the ground with an 8 cm block placed 1 mm above it: after 2 s the upper one
// rests on the lower, its weight carried by the contact multipliers (lambda/h^2, N), no vertex past
// the other surface by more than the thickness, the surfaces never crossing. Warm-started, as the
// built-in scenes are: a stack's support is statically indeterminate, and 10 cold Gauss-Seidel
// iterations leave each substep a different split of it between the contacts, which keeps the
// blocks trembling at a few mm/s (40 cold iterations: 0.2 mm/s; warm: 0.01 mm/s).
TEST(BodyContact, AStackComesToRestWithTheUpperWeightCarried) {
  World w(restingSettings());
  const BodyId lower = w.addBody(block(Vec3(0.1f, 0.1f, 0.1f), 4, 4, 4, 5e4f), Vec3(-0.05f, 0.0f, -0.05f));
  const BodyId upper = w.addBody(block(Vec3(0.08f, 0.08f, 0.08f), 3, 3, 3, 5e4f), Vec3(-0.04f, 0.103f, -0.04f));
  w.addCollider(Collider::plane(Vec3::UnitY()));
  const float thickness = w.bodyContact(lower).thickness;
  for (int step = 0; step < 120; ++step) {
    w.step();
    ASSERT_LE(w.lastStep().deepestPenetration, thickness) << "step " << step;
    if (step % 10 == 9) {
      ASSERT_FALSE(crossing(surfaces(w, {lower, upper}))) << "step " << step;
    }
  }
  EXPECT_GT(w.lastStep().bodyContacts, 0u);
  float fastest = 0.0f;
  for (const Vec3& v : w.particles().v) fastest = std::max(fastest, v.norm());
  EXPECT_LT(fastest, 1e-3f);
  EXPECT_LT(std::abs(w.volumeLoss(lower)), 0.01);
  EXPECT_LT(std::abs(w.volumeLoss(upper)), 0.01);
  // Newton's third law through the multipliers, and the upper block's weight.
  const Vec3 onUpper = w.bodyContactForce(upper, lower), onLower = w.bodyContactForce(lower, upper);
  EXPECT_NEAR((onUpper + onLower).norm(), 0.0f, 1e-4f * onUpper.norm());
  const double weight = mass(w, upper) * kG;
  EXPECT_NEAR(onUpper.y(), weight, 0.03 * weight);
  EXPECT_LT(std::hypot(onUpper.x(), onUpper.z()), 0.03 * weight);
}

// Two free blocks meet head-on without gravity, friction or damping: the contacts' corrections are
// equal and opposite in momentum (w-weighted, gradients summing to zero), so the total momentum
// keeps its value up to float rounding: about one ulp of the body-frame positions per particle per
// substep, T sum m ulp(0.05 m) / h^2 over the run (docs/validation.md V8), here 2e-4 of sum m|v|.
// Elastic energy is >= 0 and XPBD only dissipates, so the kinetic energy after is at most before.
TEST(BodyContact, AHeadOnCollisionConservesMomentumAndGainsNoEnergy) {
  SolverSettings s;
  s.gravity = Vec3::Zero();
  s.substeps = 4;
  s.iterations = 10;
  s.linearDamping = 0.0f;
  World w(s);
  const BodyId a = w.addBody(block(Vec3(0.05f, 0.05f, 0.05f), 2, 2, 2, 2e5f, 2000.0f), Vec3(-0.06f, 0.0f, 0.0f));
  const BodyId b = w.addBody(block(Vec3(0.05f, 0.05f, 0.05f), 2, 2, 2, 2e5f, 1000.0f), Vec3(0.01f, 0.01f, 0.005f));
  BodyContactSettings frictionless;
  frictionless.staticFriction = frictionless.dynamicFriction = 0.0f;
  w.setBodyContact(a, frictionless);
  w.setBodyContact(b, frictionless);
  const auto bodyOf = [&](Index i) { return i < w.body(b).firstParticle ? a : b; };
  for (std::size_t i = 0; i < w.particles().size(); ++i)
    w.particles().v[i] = Vec3(bodyOf(Index(i)) == a ? 1.0f : -1.0f, 0, 0);
  const auto momentum = [&] {
    Vec3d p = Vec3d::Zero();
    for (std::size_t i = 0; i < w.particles().size(); ++i)
      p += (w.particles().v[i] / w.particles().x[i].w).cast<double>();
    return p;
  };
  const auto kinetic = [&] {
    double e = 0.0;
    for (std::size_t i = 0; i < w.particles().size(); ++i)
      e += 0.5 * w.particles().v[i].squaredNorm() / w.particles().x[i].w;
    return e;
  };
  const Vec3d p0 = momentum();
  const double e0 = kinetic(), scale = mass(w, a) + mass(w, b);
  std::size_t touched = 0;
  for (int step = 0; step < 12; ++step) {
    w.step();
    touched += w.lastStep().bodyContacts;
  }
  EXPECT_GT(touched, 0u) << "the blocks never met";
  EXPECT_LT((momentum() - p0).norm(), 2e-4 * scale);
  EXPECT_LE(kinetic(), e0 * (1.0 + 1e-4));
  EXPECT_LT(w.position(w.particleIndex(a, 0)).x(), w.position(w.particleIndex(b, 0)).x());
  EXPECT_FALSE(crossing(surfaces(w, {a, b})));
}

// A 1 cm slab at 5 m/s meets a block: at 60 Hz with 8 substeps it travels its own thickness in
// each substep, so a contact found only where the slab already is would let it pass. The contact
// plane taken at the substep's start stops it on its side.
TEST(BodyContact, AFastThinBodyDoesNotTunnel) {
  SolverSettings s;
  s.gravity = Vec3::Zero();
  s.substeps = 8;
  s.iterations = 5;
  World w(s);
  const BodyId slab = w.addBody(block(Vec3(0.1f, 0.01f, 0.1f), 4, 1, 4, 1e5f), Vec3(-0.05f, 0.05f, -0.05f));
  const BodyId target = w.addBody(block(Vec3(0.04f, 0.04f, 0.04f), 2, 2, 2, 1e5f), Vec3(-0.02f, 0.0f, -0.02f));
  for (Index i = 0; i < w.body(slab).particleCount; ++i) w.particles().v[w.particleIndex(slab, i)] = Vec3(0, -5.0f, 0);
  for (int step = 0; step < 12; ++step) {
    w.step();
    ASSERT_LE(w.lastStep().deepestPenetration, 2.0f * w.bodyContact(slab).thickness) << "step " << step;
  }
  float slabLowest = 1e9f, targetHighest = -1e9f;
  for (Index i = 0; i < w.body(slab).particleCount; ++i)
    slabLowest = std::min(slabLowest, w.particles().x[w.particleIndex(slab, i)].pos.y());
  for (Index i = 0; i < w.body(target).particleCount; ++i)
    targetHighest = std::max(targetHighest, w.particles().x[w.particleIndex(target, i)].pos.y());
  EXPECT_GT(slabLowest, targetHighest - 0.005f) << "the slab went into or through the block";
  EXPECT_FALSE(crossing(surfaces(w, {slab, target})));
}

}  // namespace
}  // namespace vrd

namespace vrd {
namespace {

// A soft bar on the ground, its right end (kinematic) carried over in a half turn about a pivot
// above the bar, then pressed down 5 mm into where the bar's top is: without self-contact the end
// passes into the bar; with it, the bar's surface does not cross itself at any step.
int foldCrossings(bool self) {
  SolverSettings s;
  s.substeps = 8;
  s.iterations = 10;
  s.warmStart = true;
  World w(s);
  constexpr float kLength = 0.24f, kSide = 0.02f;
  const BodyId bar = w.addBody(block(Vec3(kLength, kSide, kSide), 24, 2, 2, 1e5f));
  Collider ground = Collider::plane(Vec3::UnitY());
  ground.staticFriction = ground.dynamicFriction = 1.0f;
  w.addCollider(ground);
  BodyContactSettings contact;
  contact.self = self;
  w.setBodyContact(bar, contact);
  std::vector<Index> moved;
  std::vector<Vec3> from;
  for (Index i = 0; i < w.body(bar).particleCount; ++i) {
    const Index p = w.particleIndex(bar, i);
    if (const Vec3 x = w.particles().x[p].pos; x.x() > kLength - 1e-4f) {
      w.setInverseMass(p, 0.0f);
      moved.push_back(p);
      from.push_back(x);
    }
  }
  const float radius = 0.03f;
  const Vec3 pivot(0.6f * kLength, kSide + radius, 0.0f);
  const int turn = 60, press = 30;
  const float dt = float(s.timeStep), down = 2.0f * radius + 0.005f;
  int crossings = 0;
  for (int step = 1; step <= turn + press; ++step) {
    const float angle = float(M_PI) * float(std::min(step, turn)) / float(turn);
    const float drop = down * float(std::max(0, step - turn)) / float(press);
    const Eigen::AngleAxisf r(angle, Vec3::UnitZ());
    for (std::size_t k = 0; k < moved.size(); ++k) {
      const Vec3 goal = pivot + r * (from[k] - pivot) - Vec3(0.0f, drop, 0.0f);
      w.particles().v[moved[k]] = (goal - w.particles().x[moved[k]].pos) / dt;
    }
    w.step();
    crossings += crossing(surfaces(w, {bar}));
  }
  return crossings;
}

TEST(BodyContact, ABarFoldedOntoItselfNeverCrossesItsOwnSurface) {
  EXPECT_GT(foldCrossings(false), 0) << "without self-contact the end should pass into the bar";
  EXPECT_EQ(foldCrossings(true), 0);
}

// Two ridges of one body crossing at right angles, each a single 20 cm edge (a square bar turned
// 45 degrees about its length, one across the other): the upper bar, moved as a whole (kinematic),
// presses its ridge 1 cm into the lower one's, whose bottom ridge is held. They meet halfway along
// both edges, 10 cm from any vertex, where only an edge pair can hold them: with self-contact the
// creases are taken as edge pairs, and the surface never crosses itself.
TEST(BodyContact, CrossedRidgesOfOneBodyMeetAsEdgesNotVertices) {
  const auto run = [](bool self, std::size_t* edgePairs) {
    SolverSettings s;
    s.gravity = Vec3::Zero();
    s.substeps = 8;
    s.iterations = 10;
    World w(s);
    constexpr float kSide = 0.03f, kLength = 0.2f;
    const TetMesh bar =
        makeBoxTets(Vec3(-0.5f * kSide, -0.5f * kSide, -0.5f * kLength), Vec3(kSide, kSide, kLength), 1, 1, 1);
    const Eigen::AngleAxisf lower(float(M_PI) / 4.0f, Vec3::UnitZ());  // ridge up, along z
    const Eigen::Matrix3f upper = (Eigen::AngleAxisf(float(M_PI) / 2.0f, Vec3::UnitY()) * lower).toRotationMatrix();
    const float halfDiagonal = kSide / std::sqrt(2.0f);
    TetMesh both;
    for (const Vec3& v : bar.vertices) both.vertices.push_back(lower * v);
    for (const Vec3& v : bar.vertices)
      both.vertices.push_back(upper * v + Vec3(0.0f, 2.0f * halfDiagonal + 0.002f, 0.0f));
    both.tets = bar.tets;
    const Index n = Index(bar.vertices.size());
    for (Tet t : bar.tets) both.tets.push_back({t[0] + n, t[1] + n, t[2] + n, t[3] + n});
    Material m;
    m.elastic = ElasticModuli{1e5f, 0.3f, 1000.0f};
    const BodyId body = w.addBody(makeSoftBody(both, m, {false, true, true, false}));
    BodyContactSettings contact;
    contact.self = self;
    w.setBodyContact(body, contact);
    for (Index i = 0; i < 2 * n; ++i) {
      const Index p = w.particleIndex(body, i);
      if (i >= n || w.particles().x[p].pos.y() < -0.9f * halfDiagonal) w.setInverseMass(p, 0.0f);
    }
    const int steps = 18;
    int crossings = 0;
    for (int step = 0; step < steps; ++step) {
      for (Index i = n; i < 2 * n; ++i)  // 12 mm down over the first 12 steps (0.06 m/s), then held
        w.particles().v[w.particleIndex(body, i)] = Vec3(0.0f, step < 12 ? -0.06f : 0.0f, 0.0f);
      w.step();
      crossings += crossing(surfaces(w, {body})) ? 1 : 0;
    }
    for (const BodyContact& c : w.bodyContacts()) *edgePairs += c.firstCorners == 2 ? 1 : 0;
    return crossings;
  };
  std::size_t edgePairs = 0;
  EXPECT_GT(run(false, &edgePairs), 0) << "without self-contact the ridges should pass into each other";
  EXPECT_EQ(run(true, &edgePairs), 0);
  EXPECT_GT(edgePairs, 0u) << "the ridges should be held as a pair of edges";
}

// A body at rest touches itself nowhere: self-contact then pushes nothing, and the block settles
// bit for bit as it does without it.
TEST(BodyContact, SelfContactLeavesABodyAtRestAsItWas) {
  const auto settle = [](bool self) {
    SolverSettings s;
    s.substeps = 4;
    s.warmStart = true;
    World w(s);
    const BodyId b = w.addBody(block(Vec3(0.1f, 0.05f, 0.1f), 4, 2, 4, 3e4f));
    w.addCollider(Collider::plane(Vec3::UnitY()));
    BodyContactSettings contact;
    contact.self = self;
    w.setBodyContact(b, contact);
    std::size_t pushed = 0;
    for (int step = 0; step < 60; ++step) {
      w.step();
      pushed += w.lastStep().bodyContacts;
    }
    EXPECT_EQ(pushed, 0u);
    return w.particles().x;
  };
  const std::vector<Point> with = settle(true), without = settle(false);
  for (std::size_t i = 0; i < with.size(); ++i) ASSERT_EQ(with[i].pos, without[i].pos) << "particle " << i;
}

}  // namespace
}  // namespace vrd

namespace vrd {
namespace {

// A fingertip presses the upper of two stacked blocks: what it feels in newtons is the lower
// block's resistance through the upper one. At rest the upper block's forces balance: the
// fingertip's push plus its weight equals what the lower block pushes back with (5%: the
// multipliers of a warm-started run at rest).
TEST(BodyContact, AFingertipPressingOneBodyIntoAnotherFeelsTheOther) {
  World w(restingSettings());
  const BodyId pad = w.addBody(block(Vec3(0.1f, 0.04f, 0.1f), 4, 2, 4, 2e4f), Vec3(-0.05f, 0.0f, -0.05f));
  const BodyId top = w.addBody(block(Vec3(0.06f, 0.03f, 0.06f), 2, 2, 2, 2e5f), Vec3(-0.03f, 0.0425f, -0.03f));
  w.addCollider(Collider::plane(Vec3::UnitY()));
  for (int step = 0; step < 60; ++step) w.step();
  const float radius = 0.01f;
  const Vec3 above(0.0f, 0.0725f + radius + 0.005f, 0.0f);
  const FingertipId tip = w.addFingertip(above, radius, 0.0f, FingertipContactMode::Triangles);
  for (int step = 1; step <= 90; ++step) {  // down 1 cm into the top in 1 s, then hold 0.5 s
    w.moveFingertip(tip, above - Vec3(0.0f, 0.015f * float(std::min(step, 60)) / 60.0f, 0.0f));
    w.step();
  }
  const float push = -w.fingertipForce(tip).y();  // the fingertip pushes the body down
  const float weight = float(mass(w, top)) * kG;
  const float support = w.bodyContactForce(top, pad).y();
  EXPECT_GT(push, 2.0f * weight) << "the fingertip should press hard enough for the test to mean something";
  EXPECT_NEAR(support, push + weight, 0.05f * (push + weight));
  EXPECT_FALSE(crossing(surfaces(w, {pad, top})));
}

// A pinch squeezing one body against another: two fingertips close on two 5 cm blocks side by side
// (no gravity, so nothing else pushes). At rest each block's forces balance along the squeeze: the
// thumb's push on one, the index's on the other and the contact between them are one force (5%:
// the multipliers of a warm-started run at rest), and the surfaces never cross.
TEST(BodyContact, APinchSqueezingOneBodyAgainstAnotherFeelsTheOther) {
  SolverSettings s = restingSettings();
  s.gravity = Vec3::Zero();
  World w(s);
  const Vec3 size(0.05f, 0.05f, 0.05f);
  const BodyId left = w.addBody(block(size, 3, 3, 3, 2e4f), Vec3(-0.0505f, 0.0f, -0.025f));
  const BodyId right = w.addBody(block(size, 3, 3, 3, 2e4f), Vec3(0.0005f, 0.0f, -0.025f));
  const float radius = 0.01f;
  const Vec3 thumbStart(-0.0505f - radius - 0.005f, 0.025f, 0.0f), indexStart(-thumbStart.x(), 0.025f, 0.0f);
  const FingertipId thumb = w.addFingertip(thumbStart, radius, 0.0f, FingertipContactMode::Triangles);
  const FingertipId index = w.addFingertip(indexStart, radius, 0.0f, FingertipContactMode::Triangles);
  for (int step = 1; step <= 90; ++step) {  // each 1.5 cm inwards in 1 s (1 cm into the pair), then hold 0.5 s
    const Vec3 in(0.015f * float(std::min(step, 60)) / 60.0f, 0.0f, 0.0f);
    w.moveFingertip(thumb, thumbStart + in);
    w.moveFingertip(index, indexStart - in);
    w.step();
    ASSERT_FALSE(crossing(surfaces(w, {left, right}))) << "step " << step;
  }
  const float thumbPush = w.fingertipForce(thumb).x(), indexPush = -w.fingertipForce(index).x();  // on the blocks
  const float between = w.bodyContactForce(right, left).x();  // what the left block pushes the right one with
  EXPECT_GT(thumbPush, 0.5f) << "the pinch should squeeze hard enough for the test to mean something";
  EXPECT_NEAR(indexPush, thumbPush, 0.05f * thumbPush);
  EXPECT_NEAR(between, thumbPush, 0.05f * thumbPush);
  EXPECT_NEAR(w.bodyContactForce(left, right).x(), -between, 1e-3f * between);
}

// Degenerate input: two bodies made in the same place (every vertex on another's), and a body
// thrown at 1 km/s into another: the steps stay finite and bounded.
TEST(BodyContact, OverlappingAndHugeSpeedsGiveNoNanAndNoBlowUp) {
  SolverSettings s;
  s.substeps = 4;
  World w(s);
  const auto model = block(Vec3(0.05f, 0.05f, 0.05f), 2, 2, 2, 1e5f);
  const BodyId a = w.addBody(model), b = w.addBody(model);
  const BodyId fast = w.addBody(model, Vec3(0.5f, 0.0f, 0.0f));
  (void)a;
  (void)b;
  for (Index i = 0; i < w.body(fast).particleCount; ++i)
    w.particles().v[w.particleIndex(fast, i)] = Vec3(-1000.0f, 0, 0);
  for (int step = 0; step < 30; ++step) {
    w.step();
    for (const Point& p : w.particles().x) ASSERT_TRUE(p.pos.allFinite() && p.pos.norm() < 1e3f) << "step " << step;
  }
  EXPECT_TRUE(w.takeEvents().empty());
}

}  // namespace
}  // namespace vrd
