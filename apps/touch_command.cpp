#include "touch_command.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "scene_runner.h"
#include "vrdeform/error.h"
#include "vrdeform/interact/hand_script.h"
#include "vrdeform/scene/scene_file.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;

// The standard poke (no --script): the index fingertip comes down on the body's top to one
// fingertip radius deep in kPokeDown s, holds kPokeHold s and comes back up in kPokeUp s; the run
// goes on kPokeTail s after it, long enough for the run's summary to measure the poke's signal.
constexpr double kPokeDown = 2.0, kPokeHold = 1.0, kPokeUp = 1.0, kPokeTail = 0.5;

double number(std::string_view option, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE)
    throw Error(fmt::format("--{} takes a number, got '{}'", option, text));
  return v;
}

template <typename T>
T checked(std::string_view option, const std::string& text, double lo, double hi, std::string_view range) {
  const double v = number(option, text);
  if (!(v >= lo && v <= hi)) throw Error(fmt::format("--{} must be {}, got {}", option, range, text));
  return T(v);
}

constexpr double kHuge = 1e30;
float positive(std::string_view o, const std::string& t) { return checked<float>(o, t, 1e-30, kHuge, "positive"); }
float nonNegative(std::string_view o, const std::string& t) { return checked<float>(o, t, 0, kHuge, ">= 0"); }
int whole(std::string_view o, const std::string& t, int lo, int hi) {
  const double v = checked<double>(o, t, lo, hi, fmt::format("a whole number in [{}, {}]", lo, hi));
  if (v != std::floor(v)) throw Error(fmt::format("--{} must be a whole number, got {}", o, t));
  return int(v);
}
template <typename T, std::size_t N>
T choice(std::string_view o, const std::string& t, const std::pair<std::string_view, T> (&choices)[N]) {
  std::string names;
  for (const auto& [name, value] : choices) {
    if (t == name) return value;
    names += fmt::format("{}{}", names.empty() ? "" : ", ", name);
  }
  throw Error(fmt::format("--{} must be one of {}, got '{}'", o, names, t));
}

BodySpec& body(SceneSpec& s) { return s.bodies.front(); }
ElasticModuli& moduli(SceneSpec& s) { return *body(s).material.elastic; }  // a mesh alone is soft tissue

// A scene option of `touch`: its text, as given or as recorded, applied to the scene of the mesh
// (sceneOfMesh: the scene files' defaults, which it changes). Throws vrd::Error in option terms.
struct SceneOption {
  const char* name;
  const char* type;  // in the help: what the value is
  const char* help;
  void (*apply)(SceneSpec&, const std::string&);
};

constexpr SceneOption kSceneOptions[] = {
    {"scale", "FACTOR", "Multiplies the coordinates (0.001 for millimetres; default 1)",
     [](SceneSpec& s, const std::string& t) { body(s).scale = positive("scale", t); }},
    {"tets", "N", "Surfaces: approximate tet count of the built-in mesher (default: its own, about 1000)",
     [](SceneSpec& s, const std::string& t) {
       body(s).mesher.targetTets = std::size_t(whole("tets", t, 6, 2'000'000));
     }},
    {"youngs", "PA", "Young's modulus (Pa; default 3e4, soft tissue)",
     [](SceneSpec& s, const std::string& t) { moduli(s).youngsModulus = positive("youngs", t); }},
    {"poisson", "NU", "Poisson ratio, in [0, 0.5) (default 0.45)",
     [](SceneSpec& s, const std::string& t) {
       moduli(s).poissonRatio = checked<float>("poisson", t, 0.0, std::nextafter(0.5, 0.0), "in [0, 0.5)");
     }},
    {"density", "KG_M3", "Density (kg/m^3; default 1060)",
     [](SceneSpec& s, const std::string& t) { moduli(s).density = positive("density", t); }},
    {"damping", "SECONDS", "Rayleigh (stiffness-proportional) damping time (s; default 0.005)",
     [](SceneSpec& s, const std::string& t) { moduli(s).rayleighDamping = nonNegative("damping", t); }},
    {"rate", "HZ", "Simulation steps per second (default 60)",
     [](SceneSpec& s, const std::string& t) { s.solver.timeStep = 1.0 / whole("rate", t, 1, 100'000); }},
    {"substeps", "N", "Substeps per step (default 8)",
     [](SceneSpec& s, const std::string& t) { s.solver.substeps = whole("substeps", t, 1, 1000); }},
    {"iterations", "N", "Gauss-Seidel iterations per substep (default 5)",
     [](SceneSpec& s, const std::string& t) { s.solver.iterations = whole("iterations", t, 1, 1000); }},
    {"damping-linear", "PER_SECOND", "Velocity damping (1/s; default 0)",
     [](SceneSpec& s, const std::string& t) { s.solver.linearDamping = nonNegative("damping-linear", t); }},
    {"settle", "SECONDS", "Seconds the body settles before the hand appears (default: until it is at rest, at most 20)",
     [](SceneSpec& s, const std::string& t) {
       s.settle = checked<double>("settle", t, 0, 600, "in [0, 600] seconds");
       s.settleToRest = false;
     }},
    {"hand", "g1|pro", "g1 (thumb, index, middle; the default) or pro (five fingers)",
     [](SceneSpec& s, const std::string& t) {
       static constexpr std::pair<std::string_view, bool> kHands[] = {{"g1", false}, {"pro", true}};
       s.hand.rig.fingers = (choice("hand", t, kHands) ? HandRigSettings::pro() : HandRigSettings::g1()).fingers;
     }},
    {"contact", "triangles|particles", "triangles (the default) or particles: what the fingertips touch",
     [](SceneSpec& s, const std::string& t) {
       static constexpr std::pair<std::string_view, FingertipContactMode> kContacts[] = {
           {"triangles", FingertipContactMode::Triangles}, {"particles", FingertipContactMode::Particles}};
       s.hand.rig.contact = choice("contact", t, kContacts);
     }},
    {"grasp", "local|paper|off", "local (the default), paper (eq. 35) or off",
     [](SceneSpec& s, const std::string& t) {
       static constexpr std::pair<std::string_view, int> kGrasps[] = {{"local", 0}, {"paper", 1}, {"off", 2}};
       const int g = choice("grasp", t, kGrasps);
       s.hand.grasp.enabled = g != 2;
       s.hand.grasp.mode = g == 1 ? GraspMode::Paper : GraspMode::Local;
     }},
    {"alpha", "ALPHA", "Smoothing factor per step (eq. 44), in (0, 1]",
     [](SceneSpec& s, const std::string& t) {
       s.haptics.settings.signal.alphaT = checked<float>("alpha", t, 1e-30, 1, "in (0, 1]");
     }},
    {"beta-contact", "BETA", "Weight of the contact term (eq. 43), in [0, 1]",
     [](SceneSpec& s, const std::string& t) {
       s.haptics.settings.signal.betaContact = checked<float>("beta-contact", t, 0, 1, "in [0, 1]");
     }},
    {"max-change", "PER_MS", "Largest change of a force per ms (inf: no limit)",
     [](SceneSpec& s, const std::string& t) {
       s.haptics.settings.maxChangePerMs =
           t == "inf" ? std::numeric_limits<float>::infinity() : positive("max-change", t);
     }},
};

struct TouchArgs {
  std::string mesh, script;
  bool noCalibrate = false;
  std::vector<std::string> values = std::vector<std::string>(std::size(kSceneOptions));  // as given, or empty
  RunOptions run;
};

std::string absolute(const std::string& path) {
  std::error_code ec;
  const fs::path p = fs::absolute(path, ec);
  if (ec) throw Error(fmt::format("{}: {}", path, ec.message()));
  return p.lexically_normal().string();
}

// The scene of `mesh` with the options given (`values`, as kSceneOptions) and the hand's input: a
// script, or the standard poke.
SceneSpec touchScene(const std::string& mesh, const std::vector<std::string>& values, bool calibrate,
                     const std::string& script) {
  std::error_code ec;
  if (!fs::is_regular_file(mesh, ec)) throw Error(fmt::format("{}: no such file", mesh));
  SceneSpec spec = sceneOfMesh(mesh);
  spec.description = "a mesh poked by the hand (vrdeform touch)";
  for (std::size_t i = 0; i < std::size(kSceneOptions); ++i)
    if (!values[i].empty()) kSceneOptions[i].apply(spec, values[i]);
  validateSolverSettings(spec.solver);
  validateHapticSettings(spec.haptics.settings);
  spec.haptics.calibrate = calibrate;
  if (!script.empty()) {
    spec.hand.script = script;
    spec.seconds = HandScript::load(script).duration();
    return spec;
  }
  ActionSpec poke;
  poke.action.approach = kPokeDown, poke.action.hold = kPokeHold, poke.action.release = kPokeUp;
  poke.action.depth = spec.hand.rig.geometry.fingertipRadius;
  spec.hand.actions = {poke};
  spec.seconds = poke.action.end() + kPokeTail;
  return spec;
}

// What a recording of `vrdeform touch` keeps to build the scene again: the mesh, the script and
// the scene options as they were given (the same text gives the same bits).
constexpr std::string_view kTool = "touch";

std::vector<std::pair<std::string, std::string>> recordedSettings(const TouchArgs& a) {
  std::vector<std::pair<std::string, std::string>> r{{"tool", std::string(kTool)}, {"mesh", a.mesh}};
  if (!a.script.empty()) r.emplace_back("script", a.script);
  if (a.noCalibrate) r.emplace_back("no-calibrate", "1");
  for (std::size_t i = 0; i < std::size(kSceneOptions); ++i)
    if (!a.values[i].empty()) r.emplace_back(kSceneOptions[i].name, a.values[i]);
  return r;
}

// The options of a recording back into `a` (a MESH given beside --replay replaces the recorded one).
void readRecordedSettings(const SessionRecording& r, const std::string& source, TouchArgs& a) {
  const std::string* mesh = r.setting("mesh");
  if (!mesh || r.setting("tau-contact"))
    throw Error(
        fmt::format("{}: made by an older `vrdeform touch`, whose settings this one cannot read: record it "
                    "again",
                    source));
  if (a.mesh.empty()) {
    std::error_code ec;
    if (!fs::is_regular_file(*mesh, ec))
      throw Error(
          fmt::format("{}: the recorded mesh {} is not there: if it moved, give its new path (`vrdeform "
                      "touch MESH --replay {}`; its fingerprint is checked)",
                      source, *mesh, source));
    a.mesh = *mesh;
  }
  if (const std::string* script = r.setting("script")) a.script = *script;
  a.noCalibrate = r.setting("no-calibrate") != nullptr;
  for (std::size_t i = 0; i < std::size(kSceneOptions); ++i)
    if (const std::string* v = r.setting(kSceneOptions[i].name)) a.values[i] = *v;
}

int touch(TouchArgs a, bool sceneOptionsGiven) {
  std::optional<SessionRecording> replaying = loadReplay(a.run, kTool);
  if (replaying) {
    if (!a.script.empty() || sceneOptionsGiven)
      throw Error("touch: --replay rebuilds the scene from the recording: give no --script or scene options");
    if (!a.run.osc.empty() || !a.run.forces.empty()) throw Error("touch: --replay cannot go with --osc or --forces");
    readRecordedSettings(*replaying, a.run.replay, a);
  }
  if (a.mesh.empty()) throw Error("touch: a MESH is needed (or --replay FILE)");
  a.mesh = absolute(a.mesh);
  if (!a.script.empty()) a.script = absolute(a.script);
  const SceneSpec spec = touchScene(a.mesh, a.values, !a.noCalibrate, a.script);
  return runSceneCommand(spec, a.run, recordedSettings(a), std::move(replaying));
}

}  // namespace

std::function<int()> addTouchCommand(CLI::App& app) {
  auto args = std::make_shared<TouchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "touch",
      "Poke or grasp any mesh with the hand: a scene of the mesh alone, run as `vrdeform run` runs scenes; record "
      "and replay sessions");
  cmd->add_option("mesh", args->mesh,
                  "Surface (.obj .off .stl .ply; tetrahedralised) or tet mesh (.node .ele .mesh .msh .vtk .vtu); with "
                  "--replay, the recording's (or its new path when it moved)");
  std::vector<CLI::Option*> sceneOptions;
  for (std::size_t i = 0; i < std::size(kSceneOptions); ++i)
    sceneOptions.push_back(
        cmd->add_option(fmt::format("--{}", kSceneOptions[i].name), args->values[i], kSceneOptions[i].help)
            ->type_name(kSceneOptions[i].type));
  sceneOptions.push_back(
      cmd->add_flag("--no-calibrate", args->noCalibrate, "Keep the default haptic scales (tau = 1)"));
  cmd->add_option("--script", args->script, "Hand script (docs/hand-input.md); default: the standard poke");
  addRunOptions(*cmd, args->run);
  return [args, sceneOptions]() -> int {
    const bool given =
        std::any_of(sceneOptions.begin(), sceneOptions.end(), [](const CLI::Option* o) { return o->count() > 0; });
    return touch(*args, given);
  };
}

}  // namespace vrd
