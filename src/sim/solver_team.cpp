#include "solver_team.h"

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
  invoke(job, SolverTeam{0, size_, &barrier_});
  barrier_.arriveAndWait();  // every member has finished
}

void ThreadTeam::work(int index) {
  std::uint32_t seen = 0;
  for (;;) {
    waitForChange(runs_, seen);
    seen = runs_.load(std::memory_order_acquire);
    if (stopping_) return;
    invoke_(job_, SolverTeam{index, size_, &barrier_});
    barrier_.arriveAndWait();
  }
}

}  // namespace vrd
