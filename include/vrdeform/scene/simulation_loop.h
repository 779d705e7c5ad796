#pragma once
// The simulation + haptics loop on its own thread at a fixed rate (60 Hz as in the paper, up to
// 1 kHz and beyond), independent of rendering: each step runs the hand input, the haptic session
// (grasp, XPBD step, haptic force) and the haptic outputs, then publishes a Snapshot to every
// subscribed reader. Nothing a reader does can make the loop wait (docs/loop.md).

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "vrdeform/devices/haptic_output.h"
#include "vrdeform/metrics/latency_stats.h"
#include "vrdeform/scene/scene_builder.h"
#include "vrdeform/scene/snapshot.h"

namespace vrd {

struct SimulationLoopSettings {
  std::uint64_t maxSteps = 0;  ///< steps to run; 0: until stop()
  bool realTime = true;        ///< paced by the wall clock; false: as fast as possible (tests, benchmarks)
  /// The hand, asked every step on the loop thread (also once finished: scripts hold their last
  /// frame); null: the scene's scripted hand.
  HandInput* input = nullptr;
  /// Receive each step's signal on the loop thread (they never block, by contract); released when
  /// the loop ends for any reason.
  std::vector<HapticOutput*> outputs;
};

/// How a loop kept its rate.
struct LoopStats {
  std::uint64_t steps = 0;
  std::uint64_t overruns = 0;  ///< steps whose work took longer than one period (real time or not)
  /// Real time only: times the loop fell more than kMaxLagPeriods behind its schedule and
  /// restarted the schedule from now instead of catching up in a burst.
  std::uint64_t resyncs = 0;
  double achievedRate = 0.0;  ///< (steps - 1) / (start of the last step - start of the first) (Hz)
  double wallSeconds = 0.0;   ///< start of the first step to the end of the last
  SampleStats stepMs;         ///< wall time of each step's work, publishing included (ms)
};

class SimulationLoop {
 public:
  /// Further behind its schedule than this many periods, the loop restarts the schedule from now
  /// (a resync) instead of running the missed steps back to back.
  static constexpr int kMaxLagPeriods = 3;

  /// Runs at the scene's own rate, 1 / its time step: the settled state and the calibrated haptic
  /// scales belong to that step, so a loop at 1 kHz needs a scene built with spec.solver.timeStep =
  /// 1e-3. When the scene has a hand, adds its fingertips to the world (as runScene does: one loop
  /// or run per scene at a time). `scene` must outlive the loop and is the loop's alone while it
  /// runs. Throws vrd::Error for a rate outside [1, 10000] Hz.
  SimulationLoop(BuiltScene& scene, SimulationLoopSettings settings);
  /// stop(), dropping the loop's exception.
  ~SimulationLoop();
  SimulationLoop(const SimulationLoop&) = delete;
  SimulationLoop& operator=(const SimulationLoop&) = delete;

  // --- Control: one controlling thread --------------------------------------------------------
  /// Starts the thread. Once per loop, and not after stop(): throws vrd::Error otherwise.
  void start();
  /// Ends the loop after its current step and joins it; idempotent. Rethrows an exception thrown
  /// on the loop thread (by the input, an output or the simulation), the first time.
  void stop();
  /// The loop's exception, after stop(); null when there was none (and while running).
  std::exception_ptr error() const;
  /// Latency statistics per stage, idle and contact, of every step. After stop() only: throws vrd::Error while started
  /// and not stopped.
  const LatencyRecorder& latency() const;
  /// After stop() only, as latency().
  LoopStats stats() const;
  /// The haptic session (null without a hand). While not running only, as the world.
  const HapticSession* session() const { return session_ ? &*session_ : nullptr; }
  double period() const { return dt_; }  ///< s

  // --- Any thread -------------------------------------------------------------------------------
  /// True from start() until the loop ends (maxSteps reached, stop(), or an exception).
  bool running() const { return running_.load(std::memory_order_acquire); }
  std::uint64_t steps() const { return steps_.load(std::memory_order_acquire); }  ///< completed steps
  std::uint64_t overruns() const { return overruns_.load(std::memory_order_relaxed); }
  /// A new channel, reserved for the world's size, that receives a snapshot after every step from
  /// the loop's next step on. Takes a mutex that the loop thread only ever try_locks (at the
  /// start of a step), so subscribing never stalls the loop; a step that finds it held picks the
  /// change up at a later step. Picking up a changed list is the only time the loop thread may
  /// allocate or free memory for its readers.
  std::shared_ptr<SnapshotChannel> subscribe();
  /// Stops sending to `channel` (from a later step on, as subscribe()).
  void unsubscribe(const std::shared_ptr<SnapshotChannel>& channel);
  /// Pauses the stepping (true) or resumes it, from the next period on. A paused loop publishes
  /// nothing and, in real time, keeps its schedule (no burst on resuming); the time it spends
  /// paused counts in LoopStats' wall time.
  void setPaused(bool paused);
  bool paused() const { return paused_.load(std::memory_order_acquire); }
  /// While paused: runs `n` more steps, one per period (single-stepping).
  void requestSteps(std::uint64_t n = 1);
  /// Changes the solver's settings (iterations, substeps, damping, ...) from the start of a later
  /// step, applied on the loop thread as subscribe() is picked up; the time step stays the loop's.
  /// Throws vrd::Error for invalid settings, at once on the calling thread.
  void setSolverSettings(const SolverSettings& settings);
  /// Whether snapshots carry each particle's constraint force (Snapshot::constraintForce), from
  /// the next step on; off by default, since it costs about one solver iteration a step.
  void setConstraintForces(bool on) { constraintForces_.store(on, std::memory_order_relaxed); }

 private:
  using Clock = std::chrono::steady_clock;

  void run();
  void step(std::uint64_t k);
  void publish(std::uint64_t k, double stepWallMs);
  void pickUpChannels();
  void pickUpSolverSettings();
  bool mayStep();  // not paused, or a requested step is left (taken)
  void nap();      // a paused loop that is not paced waits a millisecond (stop() wakes it)
  void pace(Clock::time_point& origin, std::uint64_t& sinceOrigin);
  void requireStopped(const char* what) const;

  BuiltScene& scene_;
  SimulationLoopSettings settings_;
  double dt_;  // the world's time step
  HandInput* input_;
  std::optional<HapticSession> session_;
  std::size_t particles_, bodies_;  // the world's, fixed while the loop exists (subscribe() reads them)

  // Subscriptions: wanted_ under the mutex; the loop thread copies it into channels_.
  std::mutex channelsMutex_;
  std::vector<std::shared_ptr<SnapshotChannel>> wanted_;
  std::atomic<bool> channelsChanged_{false};
  std::vector<std::shared_ptr<SnapshotChannel>> channels_;

  // Solver settings to apply: under the same kind of mutex, try_locked by the loop thread.
  std::mutex solverMutex_;
  std::optional<SolverSettings> pendingSolver_;
  std::atomic<bool> solverChanged_{false};
  std::atomic<bool> paused_{false};
  std::atomic<bool> constraintForces_{false};
  std::atomic<std::uint64_t> requestedSteps_{0};

  // Loop thread while running; the controlling thread after the join.
  LatencyRecorder latency_;
  RunningStats stepMs_;
  bool contact_ = false;  // this step's latency phase
  std::uint64_t resyncs_ = 0;
  Clock::time_point firstStart_, lastStart_, end_;
  std::exception_ptr error_;

  std::thread thread_;
  bool started_ = false, errorReported_ = false;  // controlling thread
  std::atomic<bool> running_{false};
  std::atomic<std::uint64_t> steps_{0}, overruns_{0};
  // Wakes a paced loop from its sleep on stop(); never taken by readers.
  std::mutex sleepMutex_;
  std::condition_variable wake_;
  std::atomic<bool> stopRequested_{false};
};

}  // namespace vrd
