#include "demo.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "vrdeform/io/vtu_sequence.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

constexpr float kSize = 0.1f;           // a 10 cm cube
constexpr float kDrop = 0.05f;          // dropped from 5 cm
constexpr float kFingerRadius = 0.02f;  // a fingertip pad: it spans several surface particles
constexpr float kPokeStart = 1.5f, kPokeDown = 1.0f, kPokeHold = 0.5f;  // s
constexpr float kPokeDepth = 0.03f;                                     // 3 cm into the top face

Material jelly() {
  Material m;
  m.elastic = ElasticModuli{5e3f, 0.45f, 1000.0f, 0.002f};  // gelatine-like: E = 5 kPa, a 1 kg cube
  return m;
}

// Fingertip height above the cube's rest top over time: approach, press, hold, withdraw.
float fingerDepth(float t) {
  if (t < kPokeStart) return -0.02f;
  if (t < kPokeStart + kPokeDown) return -0.02f + (kPokeDepth + 0.02f) * (t - kPokeStart) / kPokeDown;
  if (t < kPokeStart + kPokeDown + kPokeHold) return kPokeDepth;
  return std::max(-0.02f, kPokeDepth - (kPokeDepth + 0.02f) * (t - kPokeStart - kPokeDown - kPokeHold) / kPokeDown);
}

}  // namespace

int runDemo(const DemoOptions& o) {
  SolverSettings settings;
  settings.substeps = o.substeps;
  settings.iterations = o.iterations;
  World world(settings);
  const TetMesh mesh = makeBoxTetsNear(Vec3(-kSize / 2, 0.0f, -kSize / 2), Vec3::Constant(kSize), o.tets);
  const auto model = makeSoftBody(mesh, jelly(), ConstraintSet::paper());
  const BodyId body = world.addBody(model, Vec3(0.0f, kDrop, 0.0f));
  world.addCollider(Collider::plane(Vec3::UnitY()));
  const float top = kSize + kFingerRadius;
  const FingertipId finger = world.addFingertip(Vec3(0.0f, top + 0.02f, 0.0f), kFingerRadius);

  std::optional<VtuSequence> saved;
  if (!o.savePath.empty()) {
    TetMesh placed = mesh;
    for (Vec3& v : placed.vertices) v.y() += kDrop;
    saved.emplace(o.savePath, placed);
  }
  const int saveEvery = std::max(1, int(std::lround(o.saveEvery / settings.timeStep)));
  std::vector<Vec3> positions(model->particleCount());

  double mass = 0.0;
  for (float w : model->invMass) mass += 1.0 / w;
  fmt::print(
      "vrdeform demo: a {:.0f} cm jelly cube ({} particles, {} tets, {:.2f} kg) dropped {:.0f} cm onto the ground,\n"
      "poked {:.0f} cm deep by a {:.0f} mm fingertip at t = {:.1f} s and released.\n",
      kSize * 100, model->particleCount(), model->tets.size(), mass, kDrop * 100, kPokeDepth * 100,
      kFingerRadius * 1000, kPokeStart);
  fmt::print(
      "Material: E = 5 kPa, nu = 0.45, rho = 1000 kg/m^3. Solver: dt = 1/{:.0f} s, {} substep(s) x {} "
      "iteration(s); constraints: {} volume, {} strain (x6), shape matching.\n\n",
      1.0f / settings.timeStep, o.substeps, o.iterations, model->volume.size(), model->strain.size());
  fmt::print("{:>6} {:>9} {:>9} {:>9} {:>10} {:>9} {:>10}\n", "t (s)", "top (cm)", "base (cm)", "vol. loss",
             "finger (N)", "contacts", "ground (N)");

  const int steps = int(std::lround(o.seconds / settings.timeStep));
  const int every = std::max(1, int(std::lround(o.reportEvery / settings.timeStep)));
  StageTimes sum;
  float peakForce = 0.0f, peakLoss = 0.0f;
  for (int s = 1; s <= steps; ++s) {
    const float t = float(s) * settings.timeStep;
    world.moveFingertip(finger, Vec3(0.0f, top - fingerDepth(t), 0.0f));
    world.step();
    for (std::size_t k = 0; k < kStageCount; ++k) sum.ms[k] += world.lastStep().times.ms[k];
    for (const SimEvent& e : world.takeEvents()) fmt::print("  event: {}\n", e.message);

    if (saved && (s % saveEvery == 0 || s == steps)) {
      for (Index i = 0; i < model->particleCount(); ++i)
        positions[i] = world.particles().x[world.particleIndex(body, i)].pos;
      saved->addFrame(t, positions);
    }
    const float force = world.fingertipForce(finger).norm();
    peakForce = std::max(peakForce, force);
    peakLoss = std::max(peakLoss, float(world.volumeLoss(body)));
    if (s % every == 0 || s == steps) {
      float highest = -1e9f, lowest = 1e9f;
      for (Index i = 0; i < model->particleCount(); ++i) {
        highest = std::max(highest, world.particles().x[world.particleIndex(body, i)].pos.y());
        lowest = std::min(lowest, world.particles().x[world.particleIndex(body, i)].pos.y());
      }
      const float h = world.substepSize();
      double ground = 0.0;
      for (float l : world.colliderContactNormalLambda()) ground += l / (h * h);
      fmt::print("{:6.2f} {:9.2f} {:9.2f} {:8.2f}% {:10.3f} {:9} {:10.3f}\n", t, highest * 100, lowest * 100,
                 100 * world.volumeLoss(body), force, world.fingertipContactCount(finger), ground);
    }
  }

  fmt::print("\nPer-stage time, mean per step (ms), over {} steps:\n", steps);
  for (std::size_t k = 0; k < kStageCount; ++k)
    if (sum.ms[k] > 0.0) fmt::print("  {:<15} {:8.4f}\n", stageName(Stage(k)), sum.ms[k] / steps);
  fmt::print("  {:<15} {:8.4f}   (the paper's Table 3: 9.27 ms for its XPBD step, Unity/C#, i7-13700K)\n", "total",
             sum.totalMs() / steps);
  fmt::print("\nPeak fingertip force {:.3f} N, peak volume loss {:.2f}%, weight {:.3f} N.\n", peakForce, 100 * peakLoss,
             mass * 9.81);
  return 0;
}

}  // namespace vrd
