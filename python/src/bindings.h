#pragma once
// The Python module's parts (docs/python.md): each binds one layer's types into the module.

#include <pybind11/pybind11.h>

#include <functional>

namespace vrd::python {

void bindMesh(pybind11::module_& m);     // meshes: reading, checking, tetrahedralising
void bindWorld(pybind11::module_& m);    // the solver: settings, materials, colliders, World
void bindHaptics(pybind11::module_& m);  // fingers and their haptic outputs
void bindDevices(pybind11::module_& m);  // the fake WEART middleware
void bindScene(pybind11::module_& m);    // scene files, built scenes and the run loop

/// For a long call that has released the GIL: polled, it says whether Ctrl-C came (Python's
/// signal handlers run, at most every 50 ms); a KeyboardInterrupt is then pending.
std::function<bool()> ctrlC();

}  // namespace vrd::python
