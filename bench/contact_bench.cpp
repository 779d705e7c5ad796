// Body contact benchmarks (Google Benchmark), each with its baseline in the same run:
//  - SelfContact/tets/self: a 10 x 10 x 20 cm block of {1k, 10k, 100k} tets pinned at one end and
//    sagging (the paper's constraint set, 5 iterations, 1 substep), self-contact off (the baseline)
//    and on. Counters: the surface's triangles, the detection and body-contact solve times per step
//    (StepReport stage times), so that detection's growth with the surface shows in one table, and
//    the contacts a step: found, and pushed (a non-zero multiplier).
//  - SelfContactEightSubsteps/tets/self: the blocks at 8 substeps of 1/480 s (the scene files'
//    default) instead of one.
//  - SelfContactOneThread/substeps/self: the 10k block on one thread (the others: as many as
//    SolverSettings::threads gives, two on a 2-core machine), at 1 and 8 substeps.
//  - Stack/tets: two such blocks, one resting on the other, contact between them on and off.

#include <benchmark/benchmark.h>

#include <algorithm>

#include "bench_block.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

std::shared_ptr<const BodyModel> block(int tets) { return makeSoftBody(benchBlock(tets), benchMaterial()); }

void pinEnd(World& world, BodyId body) {
  const BodyModel& m = *world.body(body).model;
  for (Index i = 0; i < m.particleCount(); ++i)
    if (m.restPositions[i].z() < 1e-6f) world.setInverseMass(world.particleIndex(body, i), 0.0f);
}

// The steps each case times, the same second of motion in every run (a count that depends on the
// machine's speed would average over a different part of the fall and the swing).
constexpr int kSteps = 60;

// Steps the world, then reports the detection and body-contact stage times per step as counters.
void timeSteps(benchmark::State& state, World& world, std::size_t triangles) {
  for (int s = 0; s < 10; ++s) world.step();
  double detect = 0.0, solve = 0.0;
  std::size_t contacts = 0, pushed = 0;
  float deepest = 0.0f;
  for (auto _ : state) {
    world.step();
    detect += world.lastStep().times.ms[std::size_t(Stage::Detect)];
    solve += world.lastStep().times.ms[std::size_t(Stage::BodyContact)];
    contacts += world.bodyContacts().size();
    pushed += world.lastStep().bodyContacts;
    deepest = std::max(deepest, world.lastStep().deepestPenetration);
  }
  const double n = double(state.iterations());
  state.counters["surface_triangles"] = double(triangles);
  state.counters["detect_ms"] = detect / n;
  state.counters["contact_solve_ms"] = solve / n;
  state.counters["contacts"] = double(contacts) / n;
  state.counters["pushed"] = double(pushed) / n;
  state.counters["deepest_mm"] = 1e3 * double(deepest);
}

void selfContact(benchmark::State& state, int tets, int substeps, int threads = SolverSettings::kAutoThreads) {
  SolverSettings settings;
  settings.timeStages = true;
  settings.substeps = substeps;
  settings.threads = threads;
  World world(settings);
  const auto model = block(tets);
  const BodyId body = world.addBody(model);
  pinEnd(world, body);
  BodyContactSettings contact;
  contact.self = state.range(1) != 0;
  world.setBodyContact(body, contact);
  timeSteps(state, world, model->surface.size());
}
void SelfContact(benchmark::State& state) { selfContact(state, int(state.range(0)), 1); }
BENCHMARK(SelfContact)
    ->ArgNames({"tets", "self"})
    ->ArgsProduct({{1000, 10000, 100000}, {0, 1}})
    ->Iterations(kSteps)
    ->Unit(benchmark::kMillisecond);

// The same block at the scene files' 8 substeps a step: each substep's reach is an eighth, and the
// block bends without crumpling onto itself at its clamp.
void SelfContactEightSubsteps(benchmark::State& state) { selfContact(state, int(state.range(0)), 8); }
BENCHMARK(SelfContactEightSubsteps)
    ->ArgNames({"tets", "self"})
    ->ArgsProduct({{1000, 10000, 100000}, {0, 1}})
    ->Iterations(kSteps)
    ->Unit(benchmark::kMillisecond);

void SelfContactOneThread(benchmark::State& state) { selfContact(state, 10000, int(state.range(0)), 1); }
BENCHMARK(SelfContactOneThread)
    ->ArgNames({"substeps", "self"})
    ->ArgsProduct({{1, 8}, {0, 1}})
    ->Iterations(kSteps)
    ->Unit(benchmark::kMillisecond);

void Stack(benchmark::State& state) {
  SolverSettings settings;
  settings.timeStages = true;
  World world(settings);
  const auto model = block(int(state.range(0)));
  const BodyId lower = world.addBody(model);
  const BodyId upper = world.addBody(model, Vec3(0.0f, 0.101f, 0.0f));
  pinEnd(world, lower);
  world.addCollider(Collider::plane(Vec3::UnitY()));
  world.setPairContact(lower, upper, state.range(1) != 0);
  timeSteps(state, world, 2 * model->surface.size());
}
BENCHMARK(Stack)
    ->ArgNames({"tets", "contact"})
    ->ArgsProduct({{1000, 10000}, {0, 1}})
    ->Iterations(kSteps)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace vrd

BENCHMARK_MAIN();
