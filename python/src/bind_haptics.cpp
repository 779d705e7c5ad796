// The haptic outputs from Python: per finger, what the glove gets and the force in newtons.

#include <fmt/format.h>

#include "bindings.h"
#include "vrdeform/haptics/haptic_model.h"
#include "vrdeform/interact/hand.h"

namespace py = pybind11;

namespace vrd::python {

void bindHaptics(py::module_& m) {
  py::enum_<Finger>(m, "Finger")
      .value("THUMB", Finger::Thumb)
      .value("INDEX", Finger::Index)
      .value("MIDDLE", Finger::Middle)
      .value("RING", Finger::Ring)
      .value("LITTLE", Finger::Little);
  py::class_<FingerHaptics>(m, "FingerHaptics", "One finger's haptic outputs in a step")
      .def_readonly("force", &FingerHaptics::force, "actuator value in [0, 1] (eqs. 40-44, smoothed and rate-limited)")
      .def_readonly("raw", &FingerHaptics::raw, "F_raw of eq. 43")
      .def_readonly("newtons", &FingerHaptics::newtons, "the force between fingertip and body (N)")
      .def_readonly("baseline", &FingerHaptics::baseline, "the vendor-style baseline (condition B) in [0, 1]")
      .def_readonly("contacts", &FingerHaptics::contacts, "contacts that pushed in the last substep")
      .def_readonly("depth", &FingerHaptics::depth,
                    "indentation (m): how far the fingertip has gone in since this touch began, along its first push")
      .def("__repr__", [](const FingerHaptics& f) {
        return fmt::format("FingerHaptics(force={:.4f}, newtons={:.4f}, contacts={})", f.force, f.newtons, f.contacts);
      });
  py::class_<HapticFrame>(m, "HapticFrame", "A step's haptic outputs: the paper's whole-hand value and each finger's")
      .def_readonly("paper", &HapticFrame::paper, "Algorithm 2's F_out for the whole hand")
      .def_readonly("paper_raw", &HapticFrame::paperRaw)
      .def(
          "finger", [](const HapticFrame& f, Finger finger) { return f.fingers[std::size_t(finger)]; },
          py::arg("finger"))
      .def_property_readonly("fingers", [](const HapticFrame& f) {
        return std::vector<FingerHaptics>(f.fingers.begin(), f.fingers.end());
      });
}

}  // namespace vrd::python
