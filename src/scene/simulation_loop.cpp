#include "vrdeform/scene/simulation_loop.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "vrdeform/error.h"

namespace vrd {
namespace {

double msSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

SimulationLoop::SimulationLoop(BuiltScene& scene, SimulationLoopSettings settings)
    : scene_(scene), settings_(std::move(settings)) {
  World& world = *scene_.world;
  dt_ = world.settings().timeStep;
  if (!(dt_ >= 0.999e-4 && dt_ <= 1.0))
    throw Error(fmt::format("simulation loop: the scene's rate {:g} Hz is outside [1, 10000]", 1.0 / dt_));
  input_ = settings_.input ? settings_.input : scene_.input.get();
  if (scene_.spec.hand.enabled) session_.emplace(world, scene_.session, input_ ? input_->frame(0, 0.0) : HandFrame{});
  particles_ = world.particles().size();
  bodies_ = world.bodyCount();
}

SimulationLoop::~SimulationLoop() {
  try {
    stop();
  } catch (...) {  // a destructor must not throw; error() had it
  }
}

void SimulationLoop::start() {
  if (started_ || stopRequested_.load()) throw Error("simulation loop: start() after start() or stop()");
  started_ = true;
  running_.store(true, std::memory_order_release);
  try {
    thread_ = std::thread([this] { run(); });
  } catch (...) {
    running_.store(false, std::memory_order_release);
    throw;
  }
}

void SimulationLoop::stop() {
  {
    // Under the sleep mutex, so a loop about to sleep either sees the request or gets the notify.
    std::lock_guard lock(sleepMutex_);
    stopRequested_.store(true, std::memory_order_release);
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  if (error_ && !errorReported_) {
    errorReported_ = true;
    std::rethrow_exception(error_);
  }
}

std::exception_ptr SimulationLoop::error() const { return thread_.joinable() ? nullptr : error_; }

void SimulationLoop::requireStopped(const char* what) const {
  if (thread_.joinable())
    throw Error(fmt::format("simulation loop: {} read while the loop runs; stop() it first", what));
}

const LatencyRecorder& SimulationLoop::latency() const {
  requireStopped("latency()");
  return latency_;
}

LoopStats SimulationLoop::stats() const {
  requireStopped("stats()");
  LoopStats s;
  s.steps = steps();
  s.overruns = overruns();
  s.resyncs = resyncs_;
  if (s.steps > 0) s.wallSeconds = std::chrono::duration<double>(end_ - firstStart_).count();
  const double span = std::chrono::duration<double>(lastStart_ - firstStart_).count();
  if (s.steps > 1 && span > 0.0) s.achievedRate = double(s.steps - 1) / span;
  s.stepMs = stepMs_.stats();
  return s;
}

std::shared_ptr<SnapshotChannel> SimulationLoop::subscribe() {
  auto channel = std::make_shared<SnapshotChannel>(particles_, bodies_);
  std::lock_guard lock(channelsMutex_);
  wanted_.push_back(channel);
  channelsChanged_.store(true, std::memory_order_release);
  return channel;
}

void SimulationLoop::unsubscribe(const std::shared_ptr<SnapshotChannel>& channel) {
  std::lock_guard lock(channelsMutex_);
  std::erase(wanted_, channel);
  channelsChanged_.store(true, std::memory_order_release);
}

void SimulationLoop::pickUpChannels() {
  if (!channelsChanged_.load(std::memory_order_acquire)) return;
  std::unique_lock lock(channelsMutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;  // a subscriber holds it: try again next step
  channels_ = wanted_;
  channelsChanged_.store(false, std::memory_order_relaxed);
}

void SimulationLoop::setSolverSettings(const SolverSettings& settings) {
  SolverSettings s = settings;
  s.timeStep = dt_;  // the loop's rate and the scene's calibration belong to it
  validateSolverSettings(s);
  std::lock_guard lock(solverMutex_);
  pendingSolver_ = s;
  solverChanged_.store(true, std::memory_order_release);
}

void SimulationLoop::pickUpSolverSettings() {
  if (!solverChanged_.load(std::memory_order_acquire)) return;
  std::unique_lock lock(solverMutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;  // being set: take it next step
  if (pendingSolver_) scene_.world->setSettings(*pendingSolver_);
  pendingSolver_.reset();
  solverChanged_.store(false, std::memory_order_relaxed);
}

void SimulationLoop::setPaused(bool paused) { paused_.store(paused, std::memory_order_release); }

void SimulationLoop::requestSteps(std::uint64_t n) { requestedSteps_.fetch_add(n, std::memory_order_acq_rel); }

bool SimulationLoop::mayStep() {
  if (!paused_.load(std::memory_order_acquire)) return true;
  std::uint64_t n = requestedSteps_.load(std::memory_order_acquire);
  while (n > 0 && !requestedSteps_.compare_exchange_weak(n, n - 1, std::memory_order_acq_rel)) {
  }
  return n > 0;
}

void SimulationLoop::nap() {
  std::unique_lock lock(sleepMutex_);
  wake_.wait_for(lock, std::chrono::milliseconds(1), [this] { return stopRequested_.load(std::memory_order_relaxed); });
}

void SimulationLoop::run() {
  const double periodMs = 1e3 * period();
  Clock::time_point origin = Clock::now();  // of the real-time schedule
  std::uint64_t sinceOrigin = 0;            // steps started since origin
  firstStart_ = lastStart_ = origin;
  try {
    std::uint64_t k = 0;
    for (bool first = true; settings_.maxSteps == 0 || k < settings_.maxSteps; first = false) {
      if (!first && settings_.realTime) pace(origin, sinceOrigin);
      if (stopRequested_.load(std::memory_order_acquire)) break;
      if (!mayStep()) {  // paused: a real-time loop keeps its schedule, another one naps
        if (!settings_.realTime) nap();
        continue;
      }
      lastStart_ = Clock::now();
      if (k == 0) {
        firstStart_ = origin = lastStart_;
        sinceOrigin = 0;
      }
      pickUpChannels();
      pickUpSolverSettings();
      step(k);
      publish(k, msSince(lastStart_));
      const double workMs = msSince(lastStart_);
      stepMs_.add(workMs);
      if (workMs > periodMs) overruns_.fetch_add(1, std::memory_order_relaxed);
      steps_.store(k + 1, std::memory_order_release);
      ++k;
    }
  } catch (...) {
    error_ = std::current_exception();
  }
  // A glove must not stay pressing, whatever ended the loop.
  for (HapticOutput* out : settings_.outputs) {
    try {
      out->release();
    } catch (...) {
      if (!error_) error_ = std::current_exception();
    }
  }
  end_ = Clock::now();
  running_.store(false, std::memory_order_release);
}

void SimulationLoop::step(std::uint64_t k) {
  World& world = *scene_.world;
  if (session_) {
    session_->step(input_ ? input_->frame(k, double(k) * dt_) : HandFrame{});
    contact_ = session_->inContact();
    const HapticSample sample = sampleOf(k + 1, *session_);
    for (HapticOutput* out : settings_.outputs) out->send(sample);
  } else {
    world.step();
    contact_ = false;
  }
  latency_.add(session_ ? session_->times() : world.lastStep().times, contact_);
}

void SimulationLoop::publish(std::uint64_t k, double stepWallMs) {
  if (channels_.empty()) return;
  // The constraint forces cost about an iteration: computed once, copied to the other readers.
  const bool forces = constraintForces_.load(std::memory_order_relaxed);
  const Snapshot& first = channels_.front()->back();
  for (const std::shared_ptr<SnapshotChannel>& channel : channels_) {
    Snapshot& s = channel->back();
    captureSnapshot(s, *scene_.world, session_ ? &*session_ : nullptr, k + 1, double(k + 1) * dt_, stepWallMs);
    if (!forces) continue;
    if (&s == &first)
      captureConstraintForces(s, *scene_.world);
    else
      s.constraintForce = first.constraintForce;
  }
  for (const std::shared_ptr<SnapshotChannel>& channel : channels_) channel->publish();
}

void SimulationLoop::pace(Clock::time_point& origin, std::uint64_t& sinceOrigin) {
  // Deadlines from an absolute schedule (origin + n periods, rounded once each): no drift.
  ++sinceOrigin;
  const Clock::time_point deadline = origin + std::chrono::nanoseconds(std::llround(double(sinceOrigin) * 1e9 * dt_));
  const Clock::time_point now = Clock::now();
  if (now - deadline > std::chrono::duration<double>(kMaxLagPeriods * period())) {
    origin = now;  // too far behind: start the schedule again rather than burst to catch up
    sinceOrigin = 0;
    ++resyncs_;
    return;
  }
  std::unique_lock lock(sleepMutex_);
  wake_.wait_until(lock, deadline, [this] { return stopRequested_.load(std::memory_order_relaxed); });
}

}  // namespace vrd
