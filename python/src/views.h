#pragma once
// NumPy arrays over a World's flat arrays without copying: read-only views of live state. A view
// keeps its World's Python object (and so the World) alive; while any view of a world lives, the
// world refuses to add bodies, which would move the arrays it shows.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string_view>
#include <vector>

namespace vrd {
class World;
}

namespace vrd::python {

/// A read-only float32 view of `data` with the given shape and strides (bytes), kept alive by
/// `owner`, the Python object of `world` (or of what owns it).
pybind11::array floatView(const World& world, pybind11::handle owner, const float* data, std::vector<ssize_t> shape,
                          std::vector<ssize_t> strides);

/// Throws vrd::Error when views of `world` are alive: `what` would move the memory they show.
void requireNoViews(const World& world, std::string_view what);

}  // namespace vrd::python
