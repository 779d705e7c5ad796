#pragma once
// The threads that solve one step together (SolverSettings::threads): each member runs the same
// code and takes its share of the work (sweepColours in world.cpp: a group of a big body's
// constraints, or a share of every colour), with barriers between the parts that may touch the
// same particles. What runs at once shares no particle, so the result is bit for bit the
// one-thread result.
//
// Waiting (at a barrier, or for the next step) spins briefly, since a partner is usually a few
// microseconds away, then sleeps in the kernel: on a machine busier than its cores a descheduled
// partner then costs a wake-up instead of a core spinning for a whole time slice, and an idle
// team uses no CPU. Everything is synchronised through std::atomic, which ThreadSanitizer sees.

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

namespace vrd {

/// Waits until `value` differs from `old` (acquiring what was released with the change).
void waitForChange(const std::atomic<std::uint32_t>& value, std::uint32_t old);

/// A reusable barrier for a fixed number of threads.
class TeamBarrier {
 public:
  explicit TeamBarrier(int size) : size_(size) {}
  /// Returns once all `size` threads have arrived; what each did before arriving is visible to all after.
  void arriveAndWait() {
    const std::uint32_t generation = generation_.load(std::memory_order_relaxed);
    if (arrived_.fetch_add(1, std::memory_order_acq_rel) + 1 == size_) {
      arrived_.store(0, std::memory_order_relaxed);  // published by the release below
      generation_.store(generation + 1, std::memory_order_release);
      generation_.notify_all();
      return;
    }
    waitForChange(generation_, generation);
  }

 private:
  int size_;
  std::atomic<int> arrived_{0};
  std::atomic<std::uint32_t> generation_{0};
};

/// One member's view of the team inside ThreadTeam::run (or a team of one, default-constructed).
struct SolverTeam {
  int index = 0;  ///< this thread's place in the team
  int size = 1;   ///< threads in the team
  TeamBarrier* barrier_ = nullptr;
  std::atomic<std::size_t>* tickets_ = nullptr;  // shareOut's next item

  bool leader() const { return index == 0; }
  bool last() const { return index + 1 == size; }
  /// Waits until every member has reached it; nothing in a team of one.
  void barrier() const {
    if (size > 1) barrier_->arriveAndWait();
  }
  /// work(i) for each i in [0, count), handed out one at a time as members come free. Every member
  /// calls it with the same count; it starts with a barrier, and two calls need a barrier between.
  template <typename Work>
  void shareOut(std::size_t count, Work&& work) const {
    if (size == 1) {
      for (std::size_t i = 0; i < count; ++i) work(i);
      return;
    }
    if (leader()) tickets_->store(0, std::memory_order_relaxed);  // published by the barrier
    barrier();
    for (std::size_t i; (i = tickets_->fetch_add(1, std::memory_order_relaxed)) < count;) work(i);
  }
  /// This member's share of [begin, end), cut at multiples of `align` from begin so that SIMD
  /// batches stay whole.
  std::pair<std::size_t, std::size_t> share(std::size_t begin, std::size_t end, std::size_t align) const {
    const std::size_t blocks = (end - begin + align - 1) / align;
    const auto cut = [&](int k) { return std::min(end, begin + blocks * std::size_t(k) / std::size_t(size) * align); };
    return {cut(index), cut(index + 1)};
  }
};

/// Whether a step runs on the team or on the calling thread alone. On a machine with more runnable
/// threads than cores, a member the scheduler takes off its core holds every barrier up for a time
/// slice, and one thread may be faster than two. So the steps' wall times are measured: the way
/// taken as a running mean (over about kWindow steps, so that occasional long steps count as often
/// as they come), the other way by a trial of kTrialSteps steps now and then (ended as soon as it
/// cannot win), less often the longer the choice holds, and at once when the way taken has become
/// slower than the other was. It starts alone, the safe way. Both ways give the same result, bit
/// for bit.
class TeamChoice {
 public:
  /// Whether the next step should run on the team.
  bool useTeam() const { return trialLeft_ > 0 ? !team_ : team_; }
  /// A step ran as useTeam() said and took `seconds` of wall time.
  void record(double seconds);

 private:
  static constexpr int kWindow = 32, kTrialSteps = 16, kFirstInterval = 256, kLongestInterval = 2048;
  static constexpr double kMargin = 0.9;  // the other way must be this much faster to switch to it

  bool team_ = false;
  double mean_ = 0.0;   // the way taken: running mean of its step times (s)
  int steps_ = 0;       // steps in mean_, up to kWindow
  double other_ = 0.0;  // the other way: mean of its last trial (s); 0 before one
  int interval_ = kFirstInterval, untilTrial_ = kTrialSteps;
  int trialLeft_ = 0;  // steps of the trial under way
  double trialSum_ = 0.0;
};

/// `size` threads: the caller of run() and size - 1 workers that live as long as the team and
/// sleep between runs.
class ThreadTeam {
 public:
  explicit ThreadTeam(int size);
  ~ThreadTeam();
  ThreadTeam(const ThreadTeam&) = delete;
  ThreadTeam& operator=(const ThreadTeam&) = delete;

  int size() const { return size_; }
  /// Whether the team pays on this machine now: the caller asks and reports back.
  TeamChoice& choice() { return choice_; }

  /// Runs job(member) on every member, the caller being the leader (index 0), and returns when all
  /// have finished. `job` must not throw.
  template <typename Job>
  void run(Job&& job) {
    run(&job, [](void* f, const SolverTeam& team) { (*static_cast<std::remove_reference_t<Job>*>(f))(team); });
  }

 private:
  using Invoke = void (*)(void*, const SolverTeam&);
  void run(void* job, Invoke invoke);
  void work(int index);

  int size_;
  TeamChoice choice_;
  TeamBarrier barrier_;
  std::atomic<std::size_t> tickets_{0};
  std::atomic<std::uint32_t> runs_{0};  // bumped to start a run; workers wait for it to change
  bool stopping_ = false;               // read by workers after a change of runs_
  void* job_ = nullptr;
  Invoke invoke_ = nullptr;
  std::vector<std::thread> workers_;
};

}  // namespace vrd
