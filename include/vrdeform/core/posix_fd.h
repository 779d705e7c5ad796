#pragma once
// Small POSIX helpers of the threads that talk to devices and sockets: a file descriptor that closes
// itself, a pipe that wakes a thread out of poll(), and friends.

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <string>
#include <system_error>
#include <utility>

#include "vrdeform/error.h"

namespace vrd {

/// A file descriptor that closes itself.
class Fd {
 public:
  Fd() = default;
  explicit Fd(int fd) : fd_(fd) {}
  Fd(Fd&& o) noexcept : fd_(std::exchange(o.fd_, -1)) {}
  Fd& operator=(Fd&& o) noexcept {
    if (this != &o) reset(std::exchange(o.fd_, -1));
    return *this;
  }
  ~Fd() { reset(); }
  int get() const { return fd_; }
  explicit operator bool() const { return fd_ >= 0; }
  void reset(int fd = -1) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = fd;
  }

 private:
  int fd_ = -1;
};

/// A non-blocking pipe that wakes a device thread out of poll(): poll fd() for POLLIN, notify()
/// from any thread, drain() once woken.
class WakePipe {
 public:
  WakePipe() {
    int fds[2];
    if (::pipe2(fds, O_NONBLOCK | O_CLOEXEC) != 0)
      throw Error("cannot create a pipe: " + std::error_code(errno, std::generic_category()).message());
    read_.reset(fds[0]);
    write_.reset(fds[1]);
  }
  int fd() const { return read_.get(); }
  void notify() const {
    const char byte = 1;
    [[maybe_unused]] const ssize_t n = ::write(write_.get(), &byte, 1);  // full pipe: already woken
  }
  void drain() const {
    char buffer[64];
    while (::read(read_.get(), buffer, sizeof buffer) > 0) {
    }
  }

 private:
  Fd read_, write_;
};

/// A poll() timeout for a wait of `d`: whole milliseconds, rounded up, within [0, 60 s].
inline int pollMs(std::chrono::steady_clock::duration d) {
  const auto ms = std::chrono::ceil<std::chrono::milliseconds>(d).count();
  return int(std::clamp<long long>(ms, 0, 60'000));
}

/// The text of an errno value.
inline std::string errnoText(int code) { return std::error_code(code, std::generic_category()).message(); }

}  // namespace vrd
