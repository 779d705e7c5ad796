// Scenes from Python: scene files and the built-in scenes, built and settled, run by the same loop
// as `vrdeform run` (runScene), with the hand scripted, or driven from Python, and a callback per
// step.

#include <fmt/format.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <optional>

#include "bindings.h"
#include "vrdeform/devices/glove_link.h"
#include "vrdeform/error.h"
#include "vrdeform/interact/hand_input.h"
#include "vrdeform/interact/hand_script.h"
#include "vrdeform/interact/session_recording.h"
#include "vrdeform/scene/scene_builder.h"
#include "vrdeform/scene/scene_file.h"
#include "vrdeform/scene/scene_library.h"
#include "vrdeform/scene/scene_run.h"

namespace py = pybind11;

namespace vrd::python {
namespace {

// A hand whose fingertips a Python callable places each step: hand(step, time) returns the five
// fingertip centres (thumb to little) as a (5, 3) array, or None when it is done.
class PythonHand final : public HandInput {
 public:
  explicit PythonHand(py::function hand) : hand_(std::move(hand)) {}
  ~PythonHand() override {
    py::gil_scoped_acquire gil;
    hand_ = py::function();
  }

  HandFrame frame(std::uint64_t step, double time) override {
    py::gil_scoped_acquire gil;
    py::object r;
    try {
      r = hand_(step, time);
    } catch (py::error_already_set& e) {  // raised again once the run has stopped
      error = std::move(e);
      finished_ = true;
      return last_;
    }
    if (r.is_none()) {
      finished_ = true;
      return last_;
    }
    const auto tips = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(r);
    if (!tips || tips.ndim() != 2 || tips.shape(0) != kFingerCount || tips.shape(1) != 3)
      throw Error(fmt::format("hand(step, time) must return a (5, 3) array of fingertip centres or None, got {}",
                              std::string(py::str(py::repr(r)))));
    last_.direct = true;
    for (int f = 0; f < kFingerCount; ++f) {
      const Vec3 p(tips.at(f, 0), tips.at(f, 1), tips.at(f, 2));
      if (!p.allFinite()) throw Error(fmt::format("hand(step, time): fingertip {} is not finite", f));
      last_.fingertips[std::size_t(f)] = p;
    }
    return last_;
  }
  bool finished(std::uint64_t, double) const override { return finished_; }

  std::optional<py::error_already_set> error;  ///< what the callable raised

 private:
  py::function hand_;
  HandFrame last_;
  bool finished_ = false;
};

// One finished step as the callback sees it.
py::dict stepInfo(const RunStep& s) {
  py::dict d;
  d["step"] = s.step;
  d["time"] = s.time;
  d["volume_loss"] = s.volumeLoss;
  d["haptics"] = s.session ? py::cast(s.session->haptics()) : py::none();
  return d;
}

py::object summaryDict(const RunSummary& summary) {
  return py::module_::import("json").attr("loads")(summaryJson(summary));
}

}  // namespace

void bindScene(py::module_& m) {
  py::class_<SceneSpec>(m, "SceneSpec", "What a scene file says (docs/scenes.md); change it before build_scene")
      .def_readwrite("name", &SceneSpec::name)
      .def_readwrite("description", &SceneSpec::description)
      .def_readonly("source", &SceneSpec::source)
      .def_readwrite("solver", &SceneSpec::solver)
      .def_readwrite("settle", &SceneSpec::settle,
                     "s the bodies settle before the interaction (the most, with settle_to_rest)")
      .def_readwrite("settle_to_rest", &SceneSpec::settleToRest,
                     "settling ends once every particle is slower than 5 mm/s (a scene file without settle)")
      .def_readwrite("seconds", &SceneSpec::seconds, "default length of a run (s)")
      .def_property(
          "hand_enabled", [](const SceneSpec& s) { return s.hand.enabled; },
          [](SceneSpec& s, bool on) { s.hand.enabled = on; })
      .def_property(
          "calibrate", [](const SceneSpec& s) { return s.haptics.calibrate; },
          [](SceneSpec& s, bool on) { s.haptics.calibrate = on; }, "calibrate the haptic model after settling")
      .def_property_readonly("bodies", [](const SceneSpec& s) {
        std::vector<std::string> names;
        for (const BodySpec& b : s.bodies) names.push_back(b.name);
        return names;
      });

  m.def("load_scene", &loadSceneByName, py::arg("name_or_path"),
        "A built-in scene by name (liver, jelly, ...) or a scene file (.toml)");
  m.def(
      "parse_scene",
      [](const std::string& text, const std::filesystem::path& baseDir) {
        return parseScene(text, "<python>", std::filesystem::absolute(baseDir));
      },
      py::arg("text"), py::arg("base_dir") = std::filesystem::path("."),
      "A scene from TOML text; mesh paths are relative to base_dir");
  m.def(
      "scene_of_mesh",
      [](const std::filesystem::path& mesh, float scale) {
        if (!(scale > 0.0f && std::isfinite(scale)))
          throw Error(fmt::format("scene_of_mesh: scale must be a positive number, got {}", scale));
        SceneSpec spec = sceneOfMesh(mesh);
        spec.bodies.front().scale = scale;
        return spec;
      },
      py::arg("mesh"), py::arg("scale") = 1.0f,
      "The scene of one mesh on the ground with the scene files' defaults (`vrdeform touch` without its poke); "
      "scale 0.001 for a mesh in millimetres");
  m.def("builtin_scenes", [] {
    std::vector<std::string> names;
    for (const SceneEntry& e : builtinScenes()) names.push_back(e.name);
    return names;
  });

  py::class_<HandScript>(m, "HandScript", "A hand script: wrist keyframes and finger closures (docs/hand-input.md)")
      .def_static("load", &HandScript::load, py::arg("path"))
      .def_static(
          "parse", [](const std::string& text) { return HandScript::parse(text, "<python>"); }, py::arg("text"))
      .def_property_readonly("duration", &HandScript::duration, "the last keyframe's time (s)")
      .def("save", &HandScript::save, py::arg("path"));
  py::class_<SessionRecording>(
      m, "SessionRecording", "A recorded session's hand, step by step (`vrdeform touch --record`); replays bit for bit")
      .def_static("load", &SessionRecording::load, py::arg("path"))
      .def_static(
          "parse", [](const std::string& text) { return SessionRecording::parse(text, "<python>"); }, py::arg("text"))
      .def("__len__", [](const SessionRecording& r) { return r.steps.size(); })
      .def_property_readonly("settings", [](const SessionRecording& r) {
        py::dict d;
        for (const auto& [key, value] : r.settings) d[py::str(key)] = value;
        return d;
      });

  py::class_<BuiltScene>(m, "Scene", "A built and settled scene: its world, bodies and scripted hand")
      .def_readonly("spec", &BuiltScene::spec)
      .def_property_readonly(
          "world", [](BuiltScene& s) -> World& { return *s.world; }, py::return_value_policy::reference_internal,
          "the scene's World (alive as long as the scene)")
      .def_property_readonly(
          "bodies",
          [](const BuiltScene& s) {
            py::dict d;
            for (const SceneBody& b : s.bodies) d[py::str(b.name)] = b.id;
            return d;
          },
          "body name -> id in the world")
      .def_readonly("settle_seconds", &BuiltScene::settleSeconds)
      .def_property_readonly(
          "calibration",
          [](const BuiltScene& s) -> py::object {
            if (!s.calibration) return py::none();
            const HapticCalibration& c = *s.calibration;
            py::dict d;
            d["tau_contact"] = c.signal.tauContact;
            d["tau_finger_contact"] = c.signal.tauFingerContact;
            d["tau_volume"] = c.signal.tauVolume;
            d["tau_strain"] = c.signal.tauStrain;
            d["point"] = py::make_tuple(c.point.x(), c.point.y(), c.point.z());
            d["direction"] = py::make_tuple(c.direction.x(), c.direction.y(), c.direction.z());
            d["depth"] = c.depth;
            d["force"] = c.force;
            d["contacts"] = c.contacts;
            return d;
          },
          "The haptic model's calibration poke (docs/haptics.md): the tau it chose, where it pressed, how deep, "
          "with what force (N); None without one")
      .def(
          "run",
          [](BuiltScene& scene, std::optional<std::uint64_t> steps, const std::optional<std::filesystem::path>& out,
             const std::optional<py::function>& callback, const py::object& hand,
             const std::optional<std::string>& weart, const std::optional<py::function>& gloveNews) {
            if ((!hand.is_none() || weart) && !scene.spec.hand.enabled)
              throw Error("this scene has no hand (its [hand] enabled = false)");
            if (!hand.is_none() && weart) throw Error("hand and weart: one source for the hand");
            RunSettings settings;
            const double dt = scene.spec.solver.timeStep;
            settings.steps =
                steps ? *steps
                      : std::max<std::uint64_t>(1, std::uint64_t(std::min(std::round(scene.spec.seconds / dt), 1e15)));
            if (out) settings.outDir = *out;
            // The hand: the scene's script, or a Python callable, a hand script, a recording or a glove.
            std::unique_ptr<HandInput> input;
            PythonHand* pythonHand = nullptr;
            if (py::isinstance<HandScript>(hand))
              input = std::make_unique<HandScriptInput>(hand.cast<HandScript>());
            else if (py::isinstance<SessionRecording>(hand)) {
              const auto& recording = hand.cast<const SessionRecording&>();
              input = std::make_unique<RecordingInput>(recording);
              if (!steps) settings.steps = std::max<std::size_t>(1, recording.steps.size());
            } else if (!hand.is_none()) {
              if (!PyCallable_Check(hand.ptr()))
                throw Error("hand: a callable hand(step, time), a HandScript or a SessionRecording");
              auto owned = std::make_unique<PythonHand>(hand.cast<py::function>());
              pythonHand = owned.get();
              input = std::move(owned);
            }
            std::optional<GloveLink> glove;
            if (weart) {
              GloveNews news = [gloveNews](std::string_view line, bool error) {
                py::gil_scoped_acquire gil;
                if (gloveNews)
                  (*gloveNews)(std::string(line), error);
                else
                  py::print("glove:", std::string(line),
                            py::arg("file") = py::module_::import("sys").attr(error ? "stderr" : "stdout"));
              };
              const Vec3 point = scene.actions.empty() ? scene.bodies.front().top : scene.actions.front().target;
              glove.emplace(*weart, scene.session.hand, point, std::move(news));
              settings.input = &glove->input();
            } else {
              settings.input = input.get();
            }
            // Ctrl-C, the end of a Python hand, and an exception in the callback or the hand end the
            // run after the step in progress; the exception is raised once the run has stopped.
            std::optional<py::error_already_set> error;
            const auto interrupted = ctrlC();
            settings.afterStep = [&](const RunStep& s) {
              if (glove && s.session) glove->afterStep(s.session->haptics(), s.time);
              if (pythonHand && pythonHand->finished(s.step, s.time)) return false;
              if (!callback) {
                if (!interrupted()) return true;
                py::gil_scoped_acquire gil;
                error.emplace();  // the KeyboardInterrupt
                return false;
              }
              py::gil_scoped_acquire gil;
              try {
                if (PyErr_CheckSignals() != 0) throw py::error_already_set();
                const py::object r = (*callback)(stepInfo(s));
                return r.is_none() || r.cast<bool>();
              } catch (py::error_already_set& e) {
                error = std::move(e);
                return false;
              }
            };
            RunSummary summary;
            {
              py::gil_scoped_release release;
              try {
                summary = runScene(scene, settings);
              } catch (...) {
                if (glove) glove->shutdown();
                throw;
              }
              if (glove) glove->shutdown();  // every thimble released before run returns
            }
            if (pythonHand && pythonHand->error) throw std::move(*pythonHand->error);
            if (error) throw std::move(*error);
            return summaryDict(summary);
          },
          py::arg("steps") = py::none(), py::arg("out") = py::none(), py::arg("callback") = py::none(),
          py::arg("hand") = py::none(), py::arg("weart") = py::none(), py::arg("glove_news") = py::none(),
          R"(Runs the scene as `vrdeform run` does; returns its summary (summary.json's keys) as a dict.

steps: steps to run (default: the scene's seconds, or a recording's length); out: a folder for the
run's files (forces.csv, meshes, plots, summary.json), none by default; callback(step) after every
step, with a dict of step, time, volume_loss and haptics (a HapticFrame), returning False to stop.
The hand is the scene's script unless given: hand(step, time), a callable returning the five
fingertip centres (thumb to little) as a (5, 3) array, or None to end the run after that step with
the hand held where it was; a HandScript; a SessionRecording, replayed step by step; or a WEART
glove, weart="HOST[:PORT]" of its middleware, whose closures drive the hand over the body while
its thimbles get each finger's force, paced to real time (glove_news(line, error) gets the
connection's news, printed by default; every thimble is released when the run ends). The GIL is
released while the solver runs; Ctrl-C stops the run after the step in progress.)");

  m.def(
      "build_scene",
      [](const SceneSpec& spec, bool verbose) {
        SceneBuildObserver observer;
        if (verbose)
          observer.log = [](std::string_view line) {
            py::gil_scoped_acquire gil;
            py::print(std::string(line));
          };
        observer.stop = ctrlC();
        try {
          py::gil_scoped_release release;
          return buildScene(spec, observer);
        } catch (const Stopped&) {
          if (PyErr_Occurred()) throw py::error_already_set();  // the KeyboardInterrupt
          throw;
        }
      },
      py::arg("spec"), py::arg("verbose") = false,
      "Builds the scene: meshes its bodies, settles them and calibrates the haptics (as `vrdeform run` does); "
      "Ctrl-C stops it with KeyboardInterrupt");
}

}  // namespace vrd::python
