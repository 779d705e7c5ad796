#include "views.h"

#include <fmt/format.h>

#include <unordered_map>

#include "vrdeform/error.h"

namespace py = pybind11;

namespace vrd::python {
namespace {

// Views alive per world; touched only with the GIL held.
std::unordered_map<const World*, int>& liveViews() {
  static std::unordered_map<const World*, int> views;
  return views;
}

struct ViewOwner {
  const World* world;
  py::object owner;
};

}  // namespace

py::array floatView(const World& world, py::handle owner, const float* data, std::vector<ssize_t> shape,
                    std::vector<ssize_t> strides) {
  ++liveViews()[&world];
  py::capsule base(new ViewOwner{&world, py::reinterpret_borrow<py::object>(owner)}, [](void* p) {
    auto* v = static_cast<ViewOwner*>(p);
    auto& views = liveViews();
    if (--views[v->world] == 0) views.erase(v->world);
    delete v;
  });
  py::array view(py::dtype::of<float>(), std::move(shape), std::move(strides), data, base);
  py::detail::array_proxy(view.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return view;
}

void requireNoViews(const World& world, std::string_view what) {
  const auto it = liveViews().find(&world);
  if (it != liveViews().end() && it->second > 0)
    throw Error(
        fmt::format("{}: {} array view(s) of this world's state are alive and would be left pointing at "
                    "moved memory; delete them (del) or keep copies (numpy.array(view)) first",
                    what, it->second));
}

}  // namespace vrd::python
