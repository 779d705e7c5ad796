#include "vrdeform/devices/stop_signals.h"

#include <atomic>

#include "vrdeform/error.h"

namespace vrd {
namespace {

// Written by the handler, read by any thread: a lock-free atomic is async-signal-safe and race-free.
std::atomic<int> gSignal{0};
static_assert(std::atomic<int>::is_always_lock_free);
std::atomic<bool> gInstalled{false};

// The previous handlers, for a second signal of the same kind (written before installing).
struct sigaction gPreviousInt {};
struct sigaction gPreviousTerm {};

extern "C" void onStopSignal(int sig) {
  int expected = 0;
  if (gSignal.compare_exchange_strong(expected, sig)) return;
  // Asked twice: the user means it. Restore the previous disposition and let it act.
  ::sigaction(sig, sig == SIGINT ? &gPreviousInt : &gPreviousTerm, nullptr);
  ::raise(sig);
}

}  // namespace

StopSignals::StopSignals() {
  if (gInstalled.exchange(true)) throw Error("StopSignals: an instance already handles SIGINT and SIGTERM");
  gSignal.store(0);
  struct sigaction action {};
  action.sa_handler = onStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: a blocking call returns EINTR, so a loop notices sooner
  ::sigaction(SIGINT, nullptr, &gPreviousInt);
  ::sigaction(SIGTERM, nullptr, &gPreviousTerm);
  ::sigaction(SIGINT, &action, &previousInt_);
  ::sigaction(SIGTERM, &action, &previousTerm_);
}

StopSignals::~StopSignals() {
  ::sigaction(SIGINT, &previousInt_, nullptr);
  ::sigaction(SIGTERM, &previousTerm_, nullptr);
  gInstalled.store(false);
}

bool StopSignals::requested() const { return gSignal.load() != 0; }

int StopSignals::signal() const { return gSignal.load(); }

}  // namespace vrd
