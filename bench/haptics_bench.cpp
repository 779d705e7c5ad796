// Haptic model benchmarks (Google Benchmark), each beside its baseline in the same run:
//  - WorldStep/...: the XPBD step alone (the baseline), the paper's body sizes, a fingertip pressing.
//  - SessionStep/...: the same step inside a HapticSession: hand, grasp check, step, force model.
//  - ForceModel/...: the force model alone (Algorithm 2, lines 24-41, per hand and per finger);
//    the paper's Table 3 gives 0.20 ms mean "force calc" during contact (Unity/C#, i7-13700K).
// contact:0 = particle contacts (eqs. 36-39), contact:1 = surface triangles.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "vrdeform/haptics/haptic_session.h"
#include "vrdeform/mesh/primitives.h"

namespace vrd {
namespace {

// A 10 x 10 x 20 cm block of about `tets` tets on the ground, the index fingertip 5 mm into its
// top, everything settled: the steady contact state the paper's "contact" rows describe.
struct Pressed {
  World world;
  std::unique_ptr<HapticSession> session;
  HandFrame frame;

  Pressed(int tets, FingertipContactMode mode) {
    SolverSettings s;
    s.timeStages = false;
    world.setSettings(s);
    Material m;
    m.elastic = ElasticModuli{3e4f, 0.4f, 1060.0f, 0.005f};
    world.addBody(makeSoftBody(makeBoxTetsNear(Vec3(-0.05f, 0, -0.1f), Vec3(0.1f, 0.1f, 0.2f), tets), m));
    world.addCollider(Collider::plane(Vec3::UnitY()));
    for (int k = 0; k < 60; ++k) world.step();
    float top = 0.0f;  // the settled top face, near its centre
    for (const Point& x : world.particles().x)
      if (std::abs(x.pos.x()) < 0.02f && std::abs(x.pos.z()) < 0.02f) top = std::max(top, x.pos.y());
    HapticSessionSettings settings;
    settings.hand.contact = mode;
    frame.direct = true;
    for (int f = 0; f < kFingerCount; ++f) frame.fingertips[f] = Vec3(0.1f * float(f), 1.0f, 0.0f);  // parked
    const float r = settings.hand.geometry.fingertipRadius;
    frame.fingertips[int(Finger::Index)] = Vec3(0.003f, top + r - 0.005f, 0.007f);
    session = std::make_unique<HapticSession>(world, settings, frame);
    for (int k = 0; k < 60; ++k) session->step(frame);
  }
};

void WorldStep(benchmark::State& state) {
  Pressed p(int(state.range(0)), FingertipContactMode(state.range(1)));
  for (auto _ : state) p.world.step();
  state.counters["tets"] = double(p.world.body(0).model->tets.size());
}

void SessionStep(benchmark::State& state) {
  Pressed p(int(state.range(0)), FingertipContactMode(state.range(1)));
  for (auto _ : state) benchmark::DoNotOptimize(p.session->step(p.frame).paper);
}

void ForceModel(benchmark::State& state) {
  Pressed p(int(state.range(0)), FingertipContactMode(state.range(1)));
  HapticModel model;
  for (auto _ : state) benchmark::DoNotOptimize(model.update(p.world, p.session->rig(), p.session->grasp()).paper);
  state.counters["contacts"] = double(p.session->haptics().fingers[int(Finger::Index)].contacts);
  state.counters["index_force"] = p.session->haptics().fingers[int(Finger::Index)].force;
}

#define VRD_HAPTIC_BENCH(name)                    \
  BENCHMARK(name)                                 \
      ->ArgNames({"tets", "contact"})             \
      ->ArgsProduct({{770, 1713, 10000}, {0, 1}}) \
      ->Unit(benchmark::kMicrosecond)
VRD_HAPTIC_BENCH(WorldStep);
VRD_HAPTIC_BENCH(SessionStep);
VRD_HAPTIC_BENCH(ForceModel);

}  // namespace
}  // namespace vrd

BENCHMARK_MAIN();
