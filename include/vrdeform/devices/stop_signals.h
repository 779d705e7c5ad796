#pragma once
// Ctrl-C and SIGTERM as a request to stop: the handler only sets a lock-free flag, the program's
// loop polls requested() and returns normally, so destructors run (a WEART client releases the
// glove). A second signal of the same kind gets the previous disposition (usually: terminate).

#include <csignal>

namespace vrd {

/// Installs SIGINT and SIGTERM handlers; the destructor restores the previous ones. One instance
/// at a time (a second one throws vrd::Error). The flag starts cleared.
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

  /// True once SIGINT or SIGTERM arrived.
  bool requested() const;
  /// The signal that arrived (SIGINT / SIGTERM), 0 if none.
  int signal() const;

 private:
  struct sigaction previousInt_ {};
  struct sigaction previousTerm_ {};
};

}  // namespace vrd
