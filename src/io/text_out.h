#pragma once
// Formatted text output through a buffer: formatting a mesh line by line straight into an ostream is
// several times slower.

#include <fmt/format.h>

#include <iterator>
#include <ostream>
#include <utility>

#include "vrdeform/math/types.h"

namespace vrd::io {

class TextOut {
 public:
  explicit TextOut(std::ostream& out) : out_(out) {}
  ~TextOut() { flush(); }
  TextOut(const TextOut&) = delete;
  TextOut& operator=(const TextOut&) = delete;

  template <typename... Args>
  void print(fmt::format_string<Args...> format, Args&&... args) {
    fmt::format_to(std::back_inserter(buffer_), format, std::forward<Args>(args)...);
    if (buffer_.size() > (1u << 20)) flush();
  }
  /// "x y z" with nine significant digits, which read back (even through a double) as the same floats.
  void coordinates(const Vec3& v) { print("{:.9g} {:.9g} {:.9g}", v.x(), v.y(), v.z()); }
  void flush() {
    out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    buffer_.clear();
  }

 private:
  std::ostream& out_;
  fmt::memory_buffer buffer_;
};

}  // namespace vrd::io
