// import vrdeform: the engine, meshes, scenes and the haptic model from Python (docs/python.md).

#include <pybind11/pybind11.h>

#include <chrono>
#include <memory>

#include "bindings.h"
#include "vrdeform/error.h"

namespace vrd::python {

std::function<bool()> ctrlC() {
  return [last = std::make_shared<std::chrono::steady_clock::time_point>()] {
    const auto now = std::chrono::steady_clock::now();
    if (now - *last < std::chrono::milliseconds(50)) return false;
    *last = now;
    pybind11::gil_scoped_acquire gil;
    return PyErr_CheckSignals() != 0;
  };
}

}  // namespace vrd::python

PYBIND11_MODULE(_vrdeform, m) {
  m.doc() = "vrdeform: XPBD deformable bodies and their haptic force signal";
  // vrd::Error (bad input, a failed mesher, a scene that does not settle) arrives as
  // vrdeform.Error, a RuntimeError, with the message the command-line programs print.
  pybind11::register_exception<vrd::Error>(m, "Error", PyExc_RuntimeError);
  pybind11::register_exception<vrd::Stopped>(m, "Stopped", PyExc_RuntimeError);
  vrd::python::bindMesh(m);
  vrd::python::bindWorld(m);
  vrd::python::bindHaptics(m);
  vrd::python::bindDevices(m);
  vrd::python::bindScene(m);
}
