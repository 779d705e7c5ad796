// The fixed-rate simulation loop (scene/simulation_loop.h) and its lock-free snapshot channels
// (scene/snapshot.h). Timing assertions are loose on purpose: CI is a loaded 2-core VM.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>
#include <vector>

#include "test_support.h"
#include "vrdeform/scene/scene_library.h"
#include "vrdeform/scene/simulation_loop.h"

namespace vrd {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

// The liver (1,177 tets, scripted G1 hand) built for a loop at `rate`, unsettled, uncalibrated and
// with one substep of two iterations: what the loop does does not depend on the physics, and the
// tests stay quick (TSAN).
BuiltScene liver(double rate = 1000.0) {
  SceneSpec spec = loadSceneByName("liver");
  spec.solver.timeStep = float(1.0 / rate);
  spec.settle = 0.0;
  spec.haptics.calibrate = false;
  spec.solver.substeps = 1;
  spec.solver.iterations = 2;
  return buildScene(spec);
}

// Waits for a loop to end by itself; false if it still runs after `seconds`.
bool finishes(const SimulationLoop& loop, double seconds) {
  const Clock::time_point until =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  while (loop.running()) {
    if (Clock::now() > until) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

SimulationLoopSettings flatOut(std::uint64_t steps) {
  SimulationLoopSettings s;
  s.maxSteps = steps;
  s.realTime = false;
  return s;
}

// Counts what it gets; throws from send() number `throwAt` (1-based; 0: never) and can sleep in it.
class TestOutput final : public HapticOutput {
 public:
  explicit TestOutput(int throwAt = 0) : throwAt_(throwAt) {}
  void send(const HapticSample&) override {
    ++sends;
    sendTimes.push_back(Clock::now());
    if (sends == throwAt_) throw std::runtime_error("glove unplugged");
    if (sends <= slowSends) std::this_thread::sleep_for(slowFor);
  }
  void release() override { ++releases; }

  int sends = 0, releases = 0;
  int slowSends = 0;  // the first this many sends sleep for slowFor
  std::chrono::milliseconds slowFor{0};
  std::vector<Clock::time_point> sendTimes;

 private:
  int throwAt_;
};

// The scene's hand, throwing at step `throwAt`.
class ThrowingInput final : public HandInput {
 public:
  ThrowingInput(HandInput& inner, std::uint64_t throwAt) : inner_(inner), throwAt_(throwAt) {}
  HandFrame frame(std::uint64_t step, double time) override {
    if (step == throwAt_) throw std::runtime_error("tracker lost");
    return inner_.frame(step, time);
  }
  bool finished(std::uint64_t step, double time) const override { return inner_.finished(step, time); }

 private:
  HandInput& inner_;
  std::uint64_t throwAt_;
};

Snapshot numbered(std::uint64_t step, std::size_t particles) {
  Snapshot s;
  s.step = step;
  s.positions.assign(particles, Vec3::Constant(float(step)));
  return s;
}

TEST(SnapshotChannel, AReaderGetsTheNewestSkippingOlderOnes) {
  SnapshotChannel channel(4, 1);
  EXPECT_FALSE(channel.update());
  EXPECT_EQ(channel.front().step, 0u);
  for (std::uint64_t k = 1; k <= 3; ++k) {
    channel.back() = numbered(k, 4);
    channel.publish();
  }
  ASSERT_TRUE(channel.update());
  EXPECT_EQ(channel.front().step, 3u);
  EXPECT_EQ(channel.front().positions[2], Vec3::Constant(3.0f));
  EXPECT_FALSE(channel.update());  // nothing new: the same snapshot stays
  EXPECT_EQ(channel.front().step, 3u);
  channel.back() = numbered(4, 4);
  channel.publish();
  Snapshot copy;
  ASSERT_TRUE(channel.read(copy));
  EXPECT_EQ(copy.step, 4u);
  EXPECT_FALSE(channel.read(copy));
}

// Capacity reserved up front: the writer refills slots without reallocating.
TEST(SnapshotChannel, SlotsKeepTheirCapacity) {
  SnapshotChannel channel(100, 2);
  std::vector<const Vec3*> buffers;
  for (std::uint64_t k = 1; k <= 9; ++k) {
    Snapshot& s = channel.back();
    EXPECT_GE(s.positions.capacity(), 100u);
    s.positions.resize(100);
    buffers.push_back(s.positions.data());
    channel.publish();
    if (k % 2 == 0) channel.update();
  }
  std::sort(buffers.begin(), buffers.end());
  EXPECT_LE(std::unique(buffers.begin(), buffers.end()) - buffers.begin(), 3);
}

// A reader racing the writer only ever sees whole snapshots, newer each time (TSAN checks the rest).
TEST(SnapshotChannel, AConcurrentReaderNeverSeesATornSnapshot) {
  constexpr std::uint64_t kSnapshots = 20000;
  constexpr std::size_t kParticles = 64;
  SnapshotChannel channel(kParticles, 1);
  std::atomic<bool> done{false};
  std::uint64_t torn = 0, backwards = 0, received = 0, last = 0;
  std::thread reader([&] {
    const auto check = [&] {
      const Snapshot& s = channel.front();
      ++received;
      if (s.step <= last) ++backwards;
      last = s.step;
      for (const Vec3& p : s.positions) torn += p != Vec3::Constant(float(s.step)) ? 1 : 0;
    };
    while (!done.load(std::memory_order_acquire))
      if (channel.update()) check();
    if (channel.update()) check();
  });
  for (std::uint64_t k = 1; k <= kSnapshots; ++k) {
    Snapshot& s = channel.back();
    s.step = k;
    s.positions.assign(kParticles, Vec3::Constant(float(k)));
    channel.publish();
  }
  done.store(true, std::memory_order_release);
  reader.join();
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(backwards, 0u);
  EXPECT_EQ(last, kSnapshots);
  EXPECT_GT(received, 0u);
  testing::record("received", double(received));
}

TEST(SimulationLoop, RunsAtTheScenesRateAndRejectsRatesOutOfRange) {
  BuiltScene scene = liver(500.0);
  const SolverSettings before = scene.world->settings();
  const SimulationLoop loop(scene, {});
  EXPECT_DOUBLE_EQ(loop.period(), double(float(1.0 / 500.0)));
  EXPECT_EQ(scene.world->settings().timeStep, before.timeStep);  // the loop changes nothing
  EXPECT_EQ(scene.world->settings().substeps, before.substeps);
  for (float dt : {2.0f, 1e-5f}) {
    SolverSettings bad = before;
    bad.timeStep = dt;
    scene.world->setSettings(bad);
    EXPECT_NE(testing::errorOf([&] { SimulationLoop other(scene, {}); }).find("rate"), std::string::npos) << dt;
  }
}

TEST(SimulationLoop, AsFastAsPossibleRunsExactlyMaxSteps) {
  BuiltScene scene = liver();
  const std::uint64_t before = scene.world->stepCount();
  SimulationLoop loop(scene, flatOut(150));
  loop.start();
  ASSERT_TRUE(finishes(loop, 120.0));
  loop.stop();
  EXPECT_EQ(loop.steps(), 150u);
  EXPECT_EQ(scene.world->stepCount() - before, 150u);
  EXPECT_EQ(loop.latency().frames(Phase::All), 150u);
  const LoopStats stats = loop.stats();
  EXPECT_EQ(stats.steps, 150u);
  EXPECT_EQ(stats.stepMs.count, 150u);
  EXPECT_EQ(stats.resyncs, 0u);  // no schedule when not real time
  EXPECT_GT(stats.achievedRate, 0.0);
  EXPECT_GT(loop.latency().total(Phase::All).mean, 0.0);
  testing::record("achieved_rate_hz", stats.achievedRate);
}

TEST(SimulationLoop, SnapshotsArriveWithIncreasingStepNumbers) {
  BuiltScene scene = liver();
  SimulationLoop loop(scene, flatOut(300));
  const std::shared_ptr<SnapshotChannel> channel = loop.subscribe();
  const double dt = double(scene.world->settings().timeStep);
  const std::size_t particles = scene.world->particles().size();
  loop.start();
  std::uint64_t last = 0, received = 0, backwards = 0, wrongTime = 0, wrongSize = 0;
  const Clock::time_point until = Clock::now() + 120s;
  while (Clock::now() < until) {
    const bool ended = !loop.running();  // read before the update: a finished loop has published all
    if (channel->update()) {
      const Snapshot& s = channel->front();
      ++received;
      backwards += s.step <= last ? 1 : 0;
      wrongTime += s.time != double(s.step) * dt ? 1 : 0;
      wrongSize += s.positions.size() != particles ? 1 : 0;
      last = s.step;
    }
    if (ended) break;
    std::this_thread::yield();
  }
  loop.stop();
  EXPECT_EQ(backwards, 0u);
  EXPECT_EQ(wrongTime, 0u);
  EXPECT_EQ(wrongSize, 0u);
  EXPECT_EQ(last, 300u);
  EXPECT_GT(received, 1u);
}

TEST(SimulationLoop, TheLastSnapshotEqualsTheWorldAfterStop) {
  BuiltScene scene = liver();
  SimulationLoop loop(scene, flatOut(50));
  const std::shared_ptr<SnapshotChannel> channel = loop.subscribe();
  loop.start();
  ASSERT_TRUE(finishes(loop, 60.0));
  loop.stop();
  ASSERT_TRUE(channel->update());
  const Snapshot& s = channel->front();
  const World& world = *scene.world;
  EXPECT_EQ(s.step, 50u);
  EXPECT_DOUBLE_EQ(s.time, 50.0 * double(world.settings().timeStep));
  ASSERT_EQ(s.positions.size(), world.particles().size());
  for (std::size_t i = 0; i < s.positions.size(); ++i) ASSERT_EQ(s.positions[i], world.particles().x[i].pos) << i;
  ASSERT_EQ(s.bodyFirst.size(), world.bodyCount());
  for (std::size_t b = 0; b < s.bodyFirst.size(); ++b) EXPECT_EQ(s.bodyFirst[b], world.body(BodyId(b)).firstParticle);
  const HapticSession& session = *loop.session();
  for (int f = 0; f < kFingerCount; ++f) {
    EXPECT_EQ(s.fingerPresent[f], session.rig().has(Finger(f))) << f;
    if (s.fingerPresent[f]) {
      EXPECT_EQ(s.fingertips[f], world.fingertip(session.rig().fingertip(Finger(f))).center);
    }
  }
  EXPECT_EQ(s.fingertipRadius, scene.session.hand.geometry.fingertipRadius);
  EXPECT_EQ(s.haptics.paper, session.haptics().paper);
  EXPECT_EQ(s.grasping, session.grasp().active());
  EXPECT_EQ(s.times.ms, session.times().ms);
  EXPECT_GT(s.stepWallMs, 0.0);
}

// A reader that never reads: the loop runs on as fast as without one, and the reader, when it
// finally looks, gets the newest snapshot.
TEST(SimulationLoop, AStalledReaderNeitherBlocksNorSlowsTheLoop) {
  constexpr std::uint64_t kSteps = 400;
  const auto timed = [&](bool stalledReader) {
    BuiltScene scene = liver();
    SimulationLoop loop(scene, flatOut(kSteps));
    std::shared_ptr<SnapshotChannel> channel;
    if (stalledReader) channel = loop.subscribe();
    const Clock::time_point start = Clock::now();
    loop.start();
    EXPECT_TRUE(finishes(loop, 120.0));
    const double seconds = secondsSince(start);
    loop.stop();
    EXPECT_EQ(loop.steps(), kSteps);
    if (channel) {
      EXPECT_TRUE(channel->update());
      EXPECT_EQ(channel->front().step, kSteps);
      EXPECT_FALSE(channel->update());
    }
    return seconds;
  };
  const double alone = timed(false), stalled = timed(true);
  testing::record("seconds_without_reader", alone);
  testing::record("seconds_with_stalled_reader", stalled);
  EXPECT_LT(stalled, 3.0 * alone + 1.0);  // copying positions costs a little; waiting would cost all
}

TEST(SimulationLoop, RealTimeKeepsTheRate) {
  BuiltScene scene = liver(200.0);
  SimulationLoopSettings s;
  SimulationLoop loop(scene, s);
  const Clock::time_point start = Clock::now();
  loop.start();
  std::this_thread::sleep_for(500ms);
  loop.stop();
  const double seconds = secondsSince(start);
  const LoopStats stats = loop.stats();
  testing::record("steps", double(stats.steps));
  testing::record("achieved_rate_hz", stats.achievedRate);
  testing::record("overruns", double(stats.overruns));
  // Never ahead of the schedule (at most one step per period, plus the first one at once) ...
  EXPECT_LE(double(stats.steps), seconds * 200.0 + 1.0);
  EXPECT_LE(stats.achievedRate, 200.0 * 1.001);
  // ... and at it whenever the steps fit their periods: 100 steps in 0.5 s, loosely. A machine so
  // loaded (or a sanitizer so slow) that steps overrun cannot hold any rate; that is not the pacing.
  if (stats.overruns == 0) {
    EXPECT_GE(stats.steps, 60u);
    EXPECT_GE(stats.achievedRate, 120.0);
  }
}

TEST(SimulationLoop, StopWakesASleepingLoop) {
  BuiltScene scene = liver(1.0);
  SimulationLoopSettings s;
  SimulationLoop loop(scene, s);
  loop.start();
  const Clock::time_point until = Clock::now() + 60s;
  while (loop.steps() < 1 && Clock::now() < until) std::this_thread::sleep_for(1ms);
  std::this_thread::sleep_for(20ms);  // into the sleep before step 2
  const Clock::time_point stopping = Clock::now();
  loop.stop();
  EXPECT_LT(secondsSince(stopping), 0.5);
  EXPECT_EQ(loop.steps(), 1u);
  EXPECT_FALSE(loop.running());
  loop.stop();  // idempotent
  EXPECT_NE(testing::errorOf([&] { loop.start(); }).find("start()"), std::string::npos);
}

// An output that stalls for 20 periods: the overruns are counted and the loop restarts its
// schedule rather than running the missed steps back to back.
TEST(SimulationLoop, AfterFallingBehindItResyncsInsteadOfBursting) {
  BuiltScene scene = liver();
  TestOutput slow;
  slow.slowSends = 5;
  slow.slowFor = 20ms;
  SimulationLoopSettings s;
  s.maxSteps = 5 + 60;
  s.outputs = {&slow};
  SimulationLoop loop(scene, s);
  loop.start();
  ASSERT_TRUE(finishes(loop, 60.0));
  loop.stop();
  const LoopStats stats = loop.stats();
  EXPECT_GE(stats.overruns, 5u);
  EXPECT_GE(stats.resyncs, 1u);
  ASSERT_EQ(slow.sendTimes.size(), 65u);
  // The 60 steps after the stall start at least 1 ms apart: sends 5 to 64 span 59 ms less the
  // work of step 5 (loose: a loaded VM). Bursting through the missed steps would take a few ms.
  const double after = std::chrono::duration<double>(slow.sendTimes.back() - slow.sendTimes[5]).count();
  testing::record("seconds_for_59_steps_after_stall", after);
  EXPECT_GE(after, 0.045);
}

TEST(SimulationLoop, AnOutputsExceptionSurfacesFromStopAndOutputsAreReleased) {
  BuiltScene scene = liver();
  TestOutput failing(5), other;
  SimulationLoopSettings s = flatOut(100);
  s.outputs = {&failing, &other};
  SimulationLoop loop(scene, s);
  loop.start();
  ASSERT_TRUE(finishes(loop, 60.0));
  EXPECT_THROW(
      {
        try {
          loop.stop();
        } catch (const std::runtime_error& e) {
          EXPECT_STREQ(e.what(), "glove unplugged");
          throw;
        }
      },
      std::runtime_error);
  EXPECT_EQ(loop.steps(), 4u);  // the 5th step threw before it completed
  EXPECT_EQ(failing.releases, 1);
  EXPECT_EQ(other.releases, 1);
  EXPECT_EQ(other.sends, 4);  // outputs after the failing one missed the 5th step
  EXPECT_TRUE(loop.error());
  EXPECT_NO_THROW(loop.stop());  // reported once
}

TEST(SimulationLoop, AnInputsExceptionSurfacesFromStop) {
  BuiltScene scene = liver();
  ASSERT_TRUE(scene.input);
  ThrowingInput input(*scene.input, 3);
  TestOutput output;
  SimulationLoopSettings s = flatOut(100);
  s.input = &input;
  s.outputs = {&output};
  SimulationLoop loop(scene, s);
  loop.start();
  ASSERT_TRUE(finishes(loop, 60.0));
  EXPECT_THROW(loop.stop(), std::runtime_error);
  EXPECT_EQ(loop.steps(), 3u);
  EXPECT_EQ(output.sends, 3);
  EXPECT_EQ(output.releases, 1);
}

TEST(SimulationLoop, StatsAreRefusedWhileRunningAndUnsubscribedChannelsGetNothingMore) {
  BuiltScene scene = liver();
  SimulationLoopSettings s;
  SimulationLoop loop(scene, s);
  const std::shared_ptr<SnapshotChannel> kept = loop.subscribe(), dropped = loop.subscribe();
  loop.start();
  EXPECT_NE(testing::errorOf([&] { loop.stats(); }).find("stop()"), std::string::npos);
  EXPECT_NE(testing::errorOf([&] { loop.latency(); }).find("stop()"), std::string::npos);
  const Clock::time_point until = Clock::now() + 60s;
  while (loop.steps() < 5 && Clock::now() < until) std::this_thread::sleep_for(1ms);
  loop.unsubscribe(dropped);
  const std::uint64_t unsubscribedAt = loop.steps();
  while (loop.steps() < unsubscribedAt + 20 && Clock::now() < until) std::this_thread::sleep_for(1ms);
  loop.stop();
  ASSERT_TRUE(kept->update());
  EXPECT_EQ(kept->front().step, loop.steps());
  ASSERT_TRUE(dropped->update());
  // The change is picked up at the start of a later step: at most a step or two late.
  EXPECT_LE(dropped->front().step, unsubscribedAt + 2);
  EXPECT_LT(dropped->front().step, loop.steps());
}

// Two readers copying snapshots as fast as they can while the loop runs flat out; run this one
// under the tsan preset too, where its 500 steps, each published while both readers read, take the
// longest of the threaded tests.
TEST(SimulationLoop, TwoReadersReadContinuouslyWhileItRuns500Steps) {
  constexpr std::uint64_t kSteps = 500;
  BuiltScene scene = liver();
  SimulationLoop loop(scene, flatOut(kSteps));
  const double dt = double(scene.world->settings().timeStep);
  struct Reader {
    std::shared_ptr<SnapshotChannel> channel;
    std::uint64_t received = 0, last = 0, bad = 0;
  };
  std::array<Reader, 2> readers{Reader{loop.subscribe()}, Reader{loop.subscribe()}};
  std::atomic<bool> done{false};
  std::vector<std::thread> threads;
  for (Reader& r : readers)
    threads.emplace_back([&r, &done, dt] {
      Snapshot s;
      const auto take = [&] {
        ++r.received;
        r.bad += s.step <= r.last || s.time != double(s.step) * dt || s.positions.empty() ? 1 : 0;
        for (const Vec3& p : s.positions) r.bad += isFinite(p) ? 0 : 1;
        r.last = s.step;
      };
      while (!done.load(std::memory_order_acquire)) {
        if (r.channel->read(s))
          take();
        else
          std::this_thread::yield();  // 3 threads on a 2-core VM: leave the loop some room
      }
      if (r.channel->read(s)) take();
    });
  loop.start();
  const bool finished = finishes(loop, 300.0);
  loop.stop();
  done.store(true, std::memory_order_release);
  for (std::thread& t : threads) t.join();
  ASSERT_TRUE(finished);
  EXPECT_EQ(loop.steps(), kSteps);
  for (const Reader& r : readers) {
    EXPECT_EQ(r.bad, 0u);
    EXPECT_EQ(r.last, kSteps);
    EXPECT_GT(r.received, 1u);
  }
  testing::record("received_0", double(readers[0].received));
  testing::record("received_1", double(readers[1].received));
}

}  // namespace
}  // namespace vrd
