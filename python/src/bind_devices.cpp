// Gloves from Python: the fake WEART middleware (for trying the glove path without a glove, and
// for tests); Scene.run(weart=...) connects to a real or fake one (bind_scene.cpp).

#include <fmt/format.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "vrdeform/devices/weart_client.h"
#include "vrdeform/testing/fake_middleware.h"

namespace py = pybind11;

namespace vrd::python {

void bindDevices(py::module_& m) {
  py::class_<weart::FakeMiddleware>(m, "FakeMiddleware", R"(A fake WEART middleware on 127.0.0.1 (docs/outputs.md).

tracking: keyframes "t thumb index middle" (seconds since the session started, closures in [0, 1],
one per line) that its glove's fingers follow; pro: the TouchDIVER Pro flavour; port: 0 for a
free one. Use it as a context manager, or start() and stop().)")
      .def(py::init([](const std::string& tracking, bool pro, std::uint16_t port) {
             weart::FakeMiddlewareSettings s;
             s.port = port;
             s.pro = pro;
             if (!tracking.empty()) s.tracking = weart::TrackingScript::parse(tracking, "tracking").source();
             return std::make_unique<weart::FakeMiddleware>(std::move(s));
           }),
           py::arg("tracking") = "", py::arg("pro") = false, py::arg("port") = 0)
      .def("start", &weart::FakeMiddleware::start)
      .def("stop", &weart::FakeMiddleware::stop, py::call_guard<py::gil_scoped_release>())
      .def("__enter__",
           [](weart::FakeMiddleware& f) -> weart::FakeMiddleware& {
             f.start();
             return f;
           })
      .def("__exit__", [](weart::FakeMiddleware& f, const py::args&) { f.stop(); })
      .def_property_readonly("port", &weart::FakeMiddleware::port)
      .def_property_readonly("endpoint",
                             [](const weart::FakeMiddleware& f) { return fmt::format("127.0.0.1:{}", f.port()); })
      .def_property_readonly("status", &weart::FakeMiddleware::status, "IDLE, RUNNING, ...")
      .def_property_readonly("connections", &weart::FakeMiddleware::connections)
      .def(
          "commands",
          [](const weart::FakeMiddleware& f) {
            std::vector<std::string> lines;
            for (const weart::ReceivedCommand& c : f.commands()) lines.push_back(weart::describe(c.command));
            return lines;
          },
          "What clients sent, one line each: 'StartFromClient TrackType1', 'force RIGHT INDEX 0.5', ...")
      .def(
          "force",
          [](const weart::FakeMiddleware& f, Finger finger) {
            return f.latchedForce(weart::HandSide::Right, weart::pointOf(finger));
          },
          py::arg("finger"), "The force the right glove's thimble of `finger` presses now, in [0, 1]");
}

}  // namespace vrd::python
