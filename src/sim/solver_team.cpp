#include "solver_team.h"

#include <algorithm>

namespace vrd {
namespace {

// A hint to the core that this thread is spinning (lets the other hyperthread run).
inline void relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

// Spins before sleeping: about the time a barrier's partner usually takes to arrive, far less than
// a scheduler's time slice.
constexpr int kSpins = 2000;

}  // namespace

void waitForChange(const std::atomic<std::uint32_t>& value, std::uint32_t old) {
  for (int spin = 0; spin < kSpins; ++spin) {
    if (value.load(std::memory_order_acquire) != old) return;
    relax();
  }
  while (value.load(std::memory_order_acquire) == old) value.wait(old, std::memory_order_acquire);
}

void TeamChoice::record(double seconds) {
  if (trialLeft_ > 0) {
    // Ended early once it cannot win: a team on a machine far busier than its cores can be ten
    // times slower, and a whole trial would cost more than the choice saves.
    trialSum_ += seconds;
    --trialLeft_;
    const bool lost = trialSum_ >= kTrialSteps * kMargin * mean_;
    if (trialLeft_ > 0 && !lost) return;
    other_ = trialSum_ / (kTrialSteps - trialLeft_);
    trialLeft_ = 0;
    if (other_ < kMargin * mean_) {
      std::swap(mean_, other_);
      steps_ = kTrialSteps;
      team_ = !team_;
      interval_ = kFirstInterval;
    } else {
      interval_ = std::min(2 * interval_, kLongestInterval);  // the choice held: try less often
    }
    untilTrial_ = interval_;
    return;
  }
  steps_ = std::min(steps_ + 1, kWindow);
  mean_ += (seconds - mean_) / steps_;
  // A trial when one is due, or at once when this way has become slower than the other was.
  if (--untilTrial_ <= 0 || (other_ > 0.0 && steps_ == kWindow && kMargin * mean_ > other_)) {
    trialLeft_ = kTrialSteps;
    trialSum_ = 0.0;
  }
}

ThreadTeam::ThreadTeam(int size) : size_(size), barrier_(size) {
  workers_.reserve(std::size_t(size - 1));
  for (int k = 1; k < size; ++k) workers_.emplace_back([this, k] { work(k); });
}

ThreadTeam::~ThreadTeam() {
  stopping_ = true;
  runs_.fetch_add(1, std::memory_order_release);
  runs_.notify_all();
  for (std::thread& t : workers_) t.join();
}

void ThreadTeam::run(void* job, Invoke invoke) {
  job_ = job;
  invoke_ = invoke;
  runs_.fetch_add(1, std::memory_order_release);  // publishes the job
  runs_.notify_all();
  invoke(job, SolverTeam{0, size_, &barrier_, &tickets_});
  barrier_.arriveAndWait();  // every member has finished
}

void ThreadTeam::work(int index) {
  std::uint32_t seen = 0;
  for (;;) {
    waitForChange(runs_, seen);
    seen = runs_.load(std::memory_order_acquire);
    if (stopping_) return;
    invoke_(job_, SolverTeam{index, size_, &barrier_, &tickets_});
    barrier_.arriveAndWait();
  }
}

}  // namespace vrd
