// What a viewer changes on a running simulation loop (scene/simulation_loop.h): pausing and
// single-stepping, solver settings applied on the loop thread between steps, and a live hand set
// from another thread (interact/live_hand_input.h). Quick under TSAN: the liver at one substep.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "vrdeform/error.h"
#include "vrdeform/interact/live_hand_input.h"
#include "vrdeform/scene/scene_library.h"
#include "vrdeform/scene/simulation_loop.h"

namespace vrd {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

BuiltScene controlledLiver() {
  SceneSpec spec = loadSceneByName("liver");
  spec.solver.timeStep = 1e-3;
  spec.settle = 0.0;
  spec.haptics.calibrate = false;
  spec.solver.substeps = 1;
  spec.solver.iterations = 2;
  return buildScene(spec);
}

// Waits until pred() holds; false after 10 s.
template <typename Pred>
bool eventually(Pred pred) {
  const Clock::time_point until = Clock::now() + 10s;
  while (!pred()) {
    if (Clock::now() > until) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

SimulationLoopSettings asFastAsItCan() {
  SimulationLoopSettings s;
  s.realTime = false;
  return s;
}

// The liver's loop, started paused, with one reader.
struct PausedLoop {
  BuiltScene scene = controlledLiver();
  SimulationLoop loop{scene, asFastAsItCan()};
  std::shared_ptr<SnapshotChannel> view = loop.subscribe();
  PausedLoop() {
    loop.setPaused(true);
    loop.start();
  }
};

TEST(LoopControls, PausedLoopStepsOnlyWhenAsked) {
  PausedLoop paused;
  SimulationLoop& loop = paused.loop;
  const auto& view = paused.view;
  std::this_thread::sleep_for(30ms);
  EXPECT_EQ(loop.steps(), 0u);  // paused from the start
  loop.requestSteps(3);
  ASSERT_TRUE(eventually([&] { return loop.steps() == 3; }));
  std::this_thread::sleep_for(30ms);
  EXPECT_EQ(loop.steps(), 3u);  // exactly the three asked for
  ASSERT_TRUE(eventually([&] { return view->update() || view->front().step == 3; }));
  EXPECT_EQ(view->front().step, 3u);
  loop.setPaused(false);
  ASSERT_TRUE(eventually([&] { return loop.steps() > 50; }));
  loop.setPaused(true);
  loop.stop();  // a paused loop stops at once
  EXPECT_FALSE(loop.running());
}

TEST(LoopControls, SnapshotsCarryConstraintForcesOnlyWhenAsked) {
  PausedLoop paused;
  SimulationLoop& loop = paused.loop;
  const auto& view = paused.view;
  loop.requestSteps(1);
  ASSERT_TRUE(eventually([&] { return view->update() && view->front().step == 1; }));
  EXPECT_TRUE(view->front().constraintForce.empty());  // off by default: it costs an iteration
  loop.setConstraintForces(true);
  loop.requestSteps(30);  // placed on the ground: by then it presses on it
  ASSERT_TRUE(eventually([&] { return view->update() && view->front().step == 31; }));
  const Snapshot& s = view->front();
  ASSERT_EQ(s.constraintForce.size(), s.positions.size());
  float largest = 0.0f;
  for (float f : s.constraintForce) {
    ASSERT_TRUE(std::isfinite(f));
    largest = std::max(largest, f);
  }
  EXPECT_GT(largest, 0.0f);  // its constraints carry its weight
  loop.setConstraintForces(false);
  loop.requestSteps(1);
  ASSERT_TRUE(eventually([&] { return view->update() && view->front().step == 32; }));
  EXPECT_TRUE(view->front().constraintForce.empty());
  loop.stop();
}

TEST(LoopControls, SolverSettingsChangeBetweenSteps) {
  BuiltScene scene = controlledLiver();
  SimulationLoopSettings settings;
  settings.realTime = false;
  SimulationLoop loop(scene, settings);
  loop.start();
  ASSERT_TRUE(eventually([&] { return loop.steps() > 5; }));
  SolverSettings s = scene.spec.solver;
  s.iterations = 7;
  s.substeps = 3;
  s.timeStep = 0.5;  // ignored: the loop keeps its rate
  loop.setSolverSettings(s);
  s.iterations = 0;
  EXPECT_THROW(loop.setSolverSettings(s), Error);  // refused at once, on this thread
  const std::uint64_t after = loop.steps() + 5;
  ASSERT_TRUE(eventually([&] { return loop.steps() > after; }));
  loop.stop();
  EXPECT_EQ(scene.world->settings().iterations, 7);
  EXPECT_EQ(scene.world->settings().substeps, 3);
  EXPECT_EQ(scene.world->settings().timeStep, 1e-3);
}

TEST(LoopControls, LiveHandMovesTheFingertipsFromAnotherThread) {
  BuiltScene scene = controlledLiver();
  HandFrame parked;
  parked.direct = true;
  for (int f = 0; f < kFingerCount; ++f) parked.fingertips[f] = Vec3(0.1f * f, 1.0f, 0.0f);
  LiveHandInput hand(parked);
  SimulationLoopSettings settings;
  settings.realTime = false;
  settings.input = &hand;
  SimulationLoop loop(scene, settings);
  auto view = loop.subscribe();
  loop.start();
  ASSERT_TRUE(eventually([&] { return view->update() && view->front().fingerPresent[1]; }));
  EXPECT_NEAR(view->front().fingertips[1].y(), 1.0f, 1e-6f);
  HandFrame moved = parked;
  for (int k = 0; k < 100; ++k) {  // many sets between two steps: the newest wins
    moved.fingertips[1] = Vec3(0.0f, 2.0f + 0.01f * float(k), 0.0f);
    hand.set(moved);
  }
  ASSERT_TRUE(eventually([&] { return view->update() && view->front().fingertips[1].y() > 2.9f; }));
  EXPECT_NEAR(view->front().fingertips[1].y(), 2.99f, 1e-5f);
  loop.stop();
  EXPECT_FALSE(hand.finished(0, 0.0));
}

}  // namespace
}  // namespace vrd
