#pragma once
// The one exception type vrdeform throws: bad input, named precisely enough to fix it.

#include <stdexcept>
#include <string>

namespace vrd {

/// Invalid input (mesh, material, settings, API argument). The message says what and where.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A long operation (meshing, settling, calibrating) ended early because its caller asked, e.g.
/// on Ctrl-C: not bad input. The message says where it stopped.
class Stopped : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace vrd
