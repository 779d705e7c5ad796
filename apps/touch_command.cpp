#include "touch_command.h"

#include <fmt/format.h>
#include <fmt/ostream.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "vrdeform/core/atomic_file.h"
#include "vrdeform/devices/csv_recorder.h"
#include "vrdeform/devices/glove_link.h"
#include "vrdeform/devices/osc_output.h"
#include "vrdeform/devices/stop_signals.h"
#include "vrdeform/error.h"
#include "vrdeform/haptics/calibration.h"
#include "vrdeform/haptics/haptic_session.h"
#include "vrdeform/interact/hand_actions.h"
#include "vrdeform/interact/hand_script.h"
#include "vrdeform/interact/session_recording.h"
#include "vrdeform/io/surface_io.h"
#include "vrdeform/io/tet_io.h"
#include "vrdeform/scene/scene_builder.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;

constexpr std::array<const char*, kFingerCount> kFingerNames{"thumb", "index", "middle", "ring", "little"};
// The standard poke (no --script): the index fingertip goes from one radius above the body's top to
// one radius deep in kPokeDown s, holds kPokeHold s and comes back up in kPokeUp s.
constexpr double kPokeDown = 2.0, kPokeHold = 1.0, kPokeUp = 1.0;
constexpr std::string_view kRecordingTool = "touch";

// Everything that decides the simulation. A recording stores all of it (keys: the option names).
struct Scene {
  std::string mesh;  // absolute path once resolved
  float scale = 1.0f;
  int tets = 800;
  float youngs = 3e4f, poisson = 0.4f, density = 1060.0f, damping = 0.005f;
  int rate = 60, substeps = 1, iterations = 5;
  float linearDamping = 2.0f;
  float settle = 3.0f;  // seconds under gravity before the hand appears
  std::string hand = "g1", contact = "triangles", grasp = "local";
  bool calibrate = true;
  float alpha = HapticSettings{}.signal.alphaT;
  float betaContact = HapticSettings{}.signal.betaContact;
  float maxChange = HapticSettings{}.maxChangePerMs;
};

struct TouchArgs {
  Scene scene;
  bool noCalibrate = false;
  std::string script, csv, record, replay, weart, osc, forces;
  double seconds = 0.0;  // 0: no cap
  double reportEvery = 0.25;
};

bool positive(double v) { return std::isfinite(v) && v > 0.0; }

void validate(const Scene& s) {
  const auto fail = [](std::string_view option, std::string_view what, auto value) {
    throw Error(fmt::format("--{} must be {}, got {}", option, what, value));
  };
  if (!positive(s.scale)) fail("scale", "a positive number", s.scale);
  if (s.tets < 6 || s.tets > 2'000'000) fail("tets", "in [6, 2000000]", s.tets);
  if (!positive(s.youngs)) fail("youngs", "a positive number of pascals", s.youngs);
  if (!(s.poisson >= 0.0f && s.poisson < 0.5f)) fail("poisson", "in [0, 0.5)", s.poisson);
  if (!positive(s.density)) fail("density", "a positive number of kg/m^3", s.density);
  if (!(std::isfinite(s.damping) && s.damping >= 0.0f)) fail("damping", "a number of seconds >= 0", s.damping);
  if (s.rate < 1 || s.rate > 100'000) fail("rate", "in [1, 100000] steps per second", s.rate);
  if (s.substeps < 1 || s.substeps > 1000) fail("substeps", "in [1, 1000]", s.substeps);
  if (s.iterations < 1 || s.iterations > 1000) fail("iterations", "in [1, 1000]", s.iterations);
  if (!(std::isfinite(s.linearDamping) && s.linearDamping >= 0.0f))
    fail("damping-linear", "a number >= 0 (1/s)", s.linearDamping);
  if (!(s.settle >= 0.0f && s.settle <= 600.0f)) fail("settle", "in [0, 600] seconds", s.settle);
  if (s.hand != "g1" && s.hand != "pro") fail("hand", "g1 or pro", s.hand);
  if (s.contact != "particles" && s.contact != "triangles") fail("contact", "particles or triangles", s.contact);
  if (s.grasp != "local" && s.grasp != "paper" && s.grasp != "off") fail("grasp", "local, paper or off", s.grasp);
  if (!(s.alpha > 0.0f && s.alpha <= 1.0f)) fail("alpha", "in (0, 1]", s.alpha);
  if (!(s.betaContact >= 0.0f && s.betaContact <= 1.0f)) fail("beta-contact", "in [0, 1]", s.betaContact);
  if (!(s.maxChange > 0.0f)) fail("max-change", "positive (inf: no limit)", s.maxChange);
}

// --- Recorded settings: floats as C hexfloats, so the replay gets the very same bits. ------------

std::string hexFloat(float v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%a", double(v));
  return buffer;
}

struct Taus {
  float contact = 1.0f, fingerContact = 1.0f, volume = 1.0f, strain = 1.0f;
};

std::vector<std::pair<std::string, std::string>> recordedSettings(const Scene& s, const Taus& tau, std::uint64_t hash,
                                                                  const std::string& version,
                                                                  const std::string& input) {
  return {{"tool", std::string(kRecordingTool)},
          {"version", version},
          {"mesh", s.mesh},
          {"mesh-hash", fmt::format("{:016x}", hash)},
          {"scale", hexFloat(s.scale)},
          {"tets", std::to_string(s.tets)},
          {"youngs", hexFloat(s.youngs)},
          {"poisson", hexFloat(s.poisson)},
          {"density", hexFloat(s.density)},
          {"damping", hexFloat(s.damping)},
          {"rate", std::to_string(s.rate)},
          {"substeps", std::to_string(s.substeps)},
          {"iterations", std::to_string(s.iterations)},
          {"damping-linear", hexFloat(s.linearDamping)},
          {"settle", hexFloat(s.settle)},
          {"hand", s.hand},
          {"contact", s.contact},
          {"grasp", s.grasp},
          {"calibrate", s.calibrate ? "1" : "0"},
          {"alpha", hexFloat(s.alpha)},
          {"beta-contact", hexFloat(s.betaContact)},
          {"max-change", hexFloat(s.maxChange)},
          {"tau-contact", hexFloat(tau.contact)},
          {"tau-finger-contact", hexFloat(tau.fingerContact)},
          {"tau-volume", hexFloat(tau.volume)},
          {"tau-strain", hexFloat(tau.strain)},
          {"input", input}};
}

class RecordedSettings {
 public:
  RecordedSettings(const SessionRecording& r, std::string source) : r_(r), source_(std::move(source)) {}

  const std::string& text(const char* key) const {
    const std::string* v = r_.setting(key);
    if (!v) throw Error(fmt::format("{}: the recording has no setting '{}'", source_, key));
    return *v;
  }
  float real(const char* key) const {
    const std::string& v = text(key);
    char* end = nullptr;
    const double d = std::strtod(v.c_str(), &end);
    if (v.empty() || end != v.c_str() + v.size())
      throw Error(fmt::format("{}: setting '{}' is not a number: '{}'", source_, key, v));
    return float(d);
  }
  int integer(const char* key) const {
    const std::string& v = text(key);
    int value = 0;
    const auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), value);
    if (v.empty() || ec != std::errc() || ptr != v.data() + v.size())
      throw Error(fmt::format("{}: setting '{}' is not an integer: '{}'", source_, key, v));
    return value;
  }

 private:
  const SessionRecording& r_;
  std::string source_;
};

// --- The scene ---------------------------------------------------------------------------------

struct Setup {
  std::unique_ptr<World> world;
  BodyId id = 0;
  std::shared_ptr<const BodyModel> model;
  std::uint64_t hash = 0;
  Vec3 top = Vec3::Zero();  // highest particle after settling
};

SolverSettings solverSettings(const Scene& s) {
  SolverSettings settings;
  settings.timeStep = 1.0 / double(s.rate);
  settings.substeps = s.substeps;
  settings.iterations = s.iterations;
  settings.linearDamping = s.linearDamping;
  return settings;
}

// Reads the mesh (tetrahedralising a surface), scales it and puts its lowest point on y = 0 with
// its bounding box centred over the origin; builds the world with the ground and settles it.
Setup buildBody(const Scene& s, bool print) {
  Setup body;
  BodySpec spec;
  spec.mesh = s.mesh;
  spec.scale = s.scale;
  spec.mesher.targetTets = std::size_t(s.tets);
  PlacedMesh placed =
      placeBodyMesh(spec, print ? SceneLog([](std::string_view line) { fmt::print("{}\n", line); }) : SceneLog());
  body.hash = placed.hash;
  TetMesh& mesh = placed.tets;

  Material material;
  material.elastic = ElasticModuli{s.youngs, s.poisson, s.density, s.damping};
  body.model = makeSoftBody(mesh, material, ConstraintSet::paper());
  body.world = std::make_unique<World>(solverSettings(s));
  body.id = body.world->addBody(body.model);
  body.world->addCollider(Collider::plane(Vec3::UnitY()));
  const long settle = std::lround(double(s.settle) * s.rate);
  for (long k = 0; k < settle; ++k) body.world->step();
  for (const SimEvent& e : body.world->takeEvents()) fmt::print("  event while settling: {}\n", e.message);

  const World& w = *body.world;
  const Body& b = w.body(body.id);
  Vec3 low = Vec3::Constant(std::numeric_limits<float>::infinity()), high = -low;
  double mass = 0.0;
  float speed = 0.0f;
  for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i) {
    const Point& p = w.particles().x[i];
    speed = std::max(speed, w.particles().v[i].norm());
    low = low.cwiseMin(p.pos), high = high.cwiseMax(p.pos);
    if (p.w > 0.0f) mass += 1.0 / p.w;
  }
  body.top = topPoint(w, body.id);
  if (!isFinite(body.top)) throw Error(fmt::format("{}: the body did not settle to finite positions", s.mesh));
  if (print) {
    fmt::print(
        "body: {} particles, {} tets, {:.3f} kg; after settling {:g} s on the ground at y = 0 (fastest particle "
        "{:.1f} mm/s):\n",
        body.model->particleCount(), body.model->tets.size(), mass, s.settle, 1e3f * speed);
    fmt::print(
        "  x [{:.4f}, {:.4f}] m, y [{:.4f}, {:.4f}] m, z [{:.4f}, {:.4f}] m; top at ({:.4f}, {:.4f}, {:.4f}) m\n",
        low.x(), high.x(), low.y(), high.y(), low.z(), high.z(), body.top.x(), body.top.y(), body.top.z());
    if (speed > 0.05f)
      fmt::print("note: the body is still moving; a longer --settle lets it come to rest before the hand appears\n");
  }
  return body;
}

HapticSessionSettings sessionSettings(const Scene& s, const Taus& tau) {
  HapticSessionSettings h;
  h.hand = s.hand == "pro" ? HandRigSettings::pro() : HandRigSettings::g1();
  h.hand.contact = s.contact == "particles" ? FingertipContactMode::Particles : FingertipContactMode::Triangles;
  h.grasp.mode = s.grasp == "paper" ? GraspMode::Paper : GraspMode::Local;
  h.grasp.enabled = s.grasp != "off";
  h.haptics.signal.alphaT = s.alpha;
  h.haptics.signal.betaContact = s.betaContact;
  h.haptics.maxChangePerMs = s.maxChange;
  h.haptics.signal.tauContact = tau.contact;
  h.haptics.signal.tauFingerContact = tau.fingerContact;
  h.haptics.signal.tauVolume = tau.volume;
  h.haptics.signal.tauStrain = tau.strain;
  validateHapticSettings(h.haptics);
  validateGraspSettings(h.grasp);
  return h;
}

void printScene(const Scene& s, const HapticSessionSettings& h) {
  std::string fingers;
  for (int f = 0; f < kFingerCount; ++f)
    if (h.hand.fingers[f]) fingers += fmt::format("{}{}", fingers.empty() ? "" : ", ", kFingerNames[f]);
  fmt::print("material: E = {:g} Pa, nu = {:g}, rho = {:g} kg/m^3, Rayleigh damping {:g} s\n", s.youngs, s.poisson,
             s.density, s.damping);
  fmt::print("solver: dt = 1/{} s, {} substep(s) x {} iteration(s), linear damping {:g} /s\n", s.rate, s.substeps,
             s.iterations, s.linearDamping);
  fmt::print("hand: {} ({}), fingertip radius {:g} mm, contact against {}, grasp {}\n", s.hand == "pro" ? "Pro" : "G1",
             fingers, 1e3f * h.hand.geometry.fingertipRadius, s.contact, s.grasp);
}

void printTaus(const Taus& tau, const Scene& s, std::string_view how) {
  fmt::print("haptics ({}): tau contact {:.6g}, tau finger contact {:.6g}, tau volume {:.6g}, tau strain {:.6g}\n", how,
             tau.contact, tau.fingerContact, tau.volume, tau.strain);
  fmt::print("  alpha {:g}, beta contact {:g}, max change {:g} per ms\n", s.alpha, s.betaContact, s.maxChange);
}

// --- Inputs --------------------------------------------------------------------------------------

// The built-in poke: the index fingertip comes down on `top` to one fingertip radius deep, holds
// and withdraws.
HandAction standardPoke(const Vec3& top, float radius) {
  HandAction poke;
  poke.target = top;
  poke.approach = kPokeDown, poke.hold = kPokeHold, poke.release = kPokeUp;
  poke.depth = radius;
  return poke;
}

// --- Output --------------------------------------------------------------------------------------

// Steps of `dt` in `seconds`, at least 1 (and no overflow for huge values).
std::uint64_t steps(double seconds, double dt) {
  const double n = std::round(seconds / dt);
  return n >= 1e18 ? std::numeric_limits<std::uint64_t>::max() : std::max<std::uint64_t>(1, std::uint64_t(n));
}

struct Tally {
  std::uint64_t steps = 0;
  float peakPaper = 0.0f;
  std::array<float, kFingerCount> peakForce{}, peakNewtons{};
  StageTimes sum;
  double wallSeconds = 0.0;
};

// Runs `input` through the session step by step (up to maxSteps), printing the timeline and
// writing the recording and the CSV as it goes. `afterStep(k)` returns false to stop.
template <typename AfterStep>
Tally drive(HapticSession& session, HandInput& input, std::uint64_t maxSteps, double reportEvery,
            SessionRecordingWriter* record, std::ostream* csv, AfterStep afterStep) {
  const HandRig& rig = session.rig();
  const double dt = session.world().settings().timeStep;
  const std::uint64_t every = steps(reportEvery, dt);
  if (csv) {
    *csv << "t,paper,paper_raw";
    for (int f = 0; f < kFingerCount; ++f)
      if (rig.has(Finger(f))) fmt::print(*csv, ",{0}_force,{0}_raw,{0}_newtons,{0}_baseline", kFingerNames[f]);
    *csv << ",grasp\n";
  }
  std::function<void(const RecordedStep&)> recordStep;
  if (record) recordStep = [record](const RecordedStep& step) { record->add(step); };
  fmt::print("\n{:>7} {:>7} {:>9} {:>7} {:>8} {:>8} {:>5}\n", "t (s)", "index", "index (N)", "paper", "baseline",
             "contacts", "grasp");
  Tally tally;
  const auto start = std::chrono::steady_clock::now();
  std::optional<HapticFrame> last;
  while (tally.steps < maxSteps) {
    if (session.run(input, 1, recordStep) == 0) break;
    const std::uint64_t k = tally.steps++;
    const HapticFrame& f = session.haptics();
    const double t = double(k + 1) * dt;
    for (std::size_t s = 0; s < kStageCount; ++s) tally.sum.ms[s] += session.times().ms[s];
    tally.peakPaper = std::max(tally.peakPaper, f.paper);
    std::size_t contacts = 0;
    for (int i = 0; i < kFingerCount; ++i) {
      tally.peakForce[i] = std::max(tally.peakForce[i], f.fingers[i].force);
      tally.peakNewtons[i] = std::max(tally.peakNewtons[i], f.fingers[i].newtons);
      contacts += f.fingers[i].contacts;
    }
    for (const SimEvent& e : session.world().takeEvents()) fmt::print("  event: {}\n", e.message);
    if (csv) {
      fmt::print(*csv, "{:.6f},{},{}", t, f.paper, f.paperRaw);
      for (int i = 0; i < kFingerCount; ++i)
        if (rig.has(Finger(i)))
          fmt::print(*csv, ",{},{},{},{}", f.fingers[i].force, f.fingers[i].raw, f.fingers[i].newtons,
                     f.fingers[i].baseline);
      *csv << (session.grasp().active() ? ",1\n" : ",0\n");
    }
    const bool go = afterStep(k);
    const bool lastStep = !go || tally.steps == maxSteps || input.finished(k + 1, double(k + 1) * dt);
    if ((k + 1) % every == 0 || lastStep) {
      const FingerHaptics& index = f.fingers[int(Finger::Index)];
      fmt::print("{:7.3f} {:7.3f} {:9.4f} {:7.3f} {:8.3f} {:8} {:>5}\n", t, index.force, index.newtons, f.paper,
                 index.baseline, contacts, session.grasp().active() ? "on" : "off");
    }
    if (!go) break;
  }
  tally.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return tally;
}

void printSummary(const Tally& t, const HandRig& rig, double dt) {
  fmt::print("\nsummary: {} steps ({:.3f} s simulated) in {:.3f} s wall time\n", t.steps, double(t.steps) * dt,
             t.wallSeconds);
  fmt::print("peak force per finger (normalised, newtons):\n");
  for (int f = 0; f < kFingerCount; ++f)
    if (rig.has(Finger(f)))
      fmt::print("  {:<7} {:6.3f} {:9.4f} N\n", kFingerNames[f], t.peakForce[f], t.peakNewtons[f]);
  fmt::print("  {:<7} {:6.3f}   (Algorithm 2's single value for the hand)\n", "paper", t.peakPaper);
  if (t.steps == 0) return;
  fmt::print("per-stage time, mean per step (ms):\n");
  double total = 0.0;
  for (std::size_t s = 0; s < kStageCount; ++s) {
    total += t.sum.ms[s];
    if (t.sum.ms[s] > 0.0 || Stage(s) == Stage::Interact || Stage(s) == Stage::Force)
      fmt::print("  {:<15} {:8.4f}\n", stageName(Stage(s)), t.sum.ms[s] / double(t.steps));
  }
  fmt::print("  {:<15} {:8.4f}\n", "total", total / double(t.steps));
}

// --- The two modes -------------------------------------------------------------------------------

std::uint64_t stepCap(double seconds, int rate) {
  return seconds > 0.0 ? steps(seconds, 1.0 / rate) : std::numeric_limits<std::uint64_t>::max();
}

int touch(const TouchArgs& a, const std::string& version) {
  if (a.scene.mesh.empty()) throw Error("touch: a MESH is needed (or --replay FILE)");
  Scene s = a.scene;
  s.calibrate = !a.noCalibrate;
  validate(s);
  std::error_code ec;
  const fs::path absolute = fs::absolute(s.mesh, ec);
  if (ec) throw Error(fmt::format("{}: {}", s.mesh, ec.message()));
  s.mesh = absolute.lexically_normal().string();

  std::optional<HandScriptInput> script;
  if (!a.script.empty()) script.emplace(HandScript::load(a.script));

  Setup body = buildBody(s, true);
  HapticSessionSettings settings = sessionSettings(s, {});
  printScene(s, settings);
  Taus tau;
  if (s.calibrate) {
    CalibrationSettings c;
    c.radius = settings.hand.geometry.fingertipRadius;
    c.contact = settings.hand.contact;
    c.point = body.top;  // where the standard poke goes
    HapticCalibration result;
    try {
      result = calibrateHaptics(*body.world, body.id, settings.haptics.signal, c);
    } catch (const Error& e) {
      throw Error(
          fmt::format("{} (a longer --settle helps a body that is still moving; --no-calibrate keeps the "
                      "default scales)",
                      e.what()));
    }
    tau = {result.signal.tauContact, result.signal.tauFingerContact, result.signal.tauVolume, result.signal.tauStrain};
    printTaus(tau, s,
              fmt::format("calibrated: a standard poke {:.1f} mm deep gave {:.4f} N over {} contacts",
                          1e3f * result.depth, result.force, result.contacts));
  } else {
    printTaus(tau, s, "not calibrated: default scales");
  }
  settings = sessionSettings(s, tau);

  std::optional<HandActionsInput> poke;
  std::optional<GloveLink> glove;
  HandInput* input = nullptr;
  std::string inputName;
  if (!a.weart.empty()) {
    glove.emplace(a.weart, settings.hand, body.top);
    input = &glove->input();
    inputName = glove->name();
  } else if (script) {
    input = &*script;
    std::error_code ignored;
    inputName = fmt::format("script {}", fs::absolute(a.script, ignored).lexically_normal().string());
    fmt::print("input: hand script {} ({} keyframes, {:g} s)\n", a.script, script->script().keyframes().size(),
               script->script().duration());
  } else {
    poke.emplace(std::vector{standardPoke(body.top, settings.hand.geometry.fingertipRadius)},
                 settings.hand.geometry.fingertipRadius);
    input = &*poke;
    inputName = "standard poke";
    fmt::print(
        "input: standard poke: the index fingertip comes down on the top to {:g} mm deep in {:g} s, holds {:g} s, "
        "withdraws in {:g} s\n",
        1e3f * settings.hand.geometry.fingertipRadius, kPokeDown, kPokeHold, kPokeUp);
  }

  // Written as the session runs, into place when it ends (a session of any length holds none of it).
  std::optional<SessionRecordingWriter> recording;
  if (!a.record.empty()) recording.emplace(a.record, recordedSettings(s, tau, body.hash, version, inputName));
  std::optional<AtomicFile> csv;
  if (!a.csv.empty()) csv.emplace(a.csv);

  HapticSession session(*body.world, settings, input->frame(0, 0.0));
  // Other outputs of the same signal: a timestamped force log and OSC over UDP (docs/outputs.md).
  std::vector<std::unique_ptr<HapticOutput>> outputs;
  if (!a.forces.empty()) outputs.push_back(std::make_unique<CsvRecorder>(a.forces, settings.hand.fingers));
  if (!a.osc.empty()) {
    const HostPort to = parseHostPort(a.osc);
    outputs.push_back(std::make_unique<OscOutput>(to.host, to.port));
  }
  const StopSignals signals;
  const auto afterStep = [&](std::uint64_t k) {
    const HapticSample sample = sampleOf(k + 1, session);
    for (const auto& out : outputs) out->send(sample);
    if (glove) glove->afterStep(session.haptics(), double(k + 1) / s.rate);  // real time
    return !signals.requested();
  };
  const std::uint64_t cap =
      glove && a.seconds <= 0.0 ? std::numeric_limits<std::uint64_t>::max() : stepCap(a.seconds, s.rate);
  const Tally tally = drive(session, *input, cap, a.reportEvery, recording ? &*recording : nullptr,
                            csv ? &csv->stream() : nullptr, afterStep);
  if (glove) glove->shutdown();  // release the glove before anything that could throw below
  for (const auto& out : outputs) out->release();
  printSummary(tally, session.rig(), 1.0 / s.rate);
  if (csv) {
    csv->commit();
    fmt::print("wrote {}\n", a.csv);
  }
  if (recording) {
    recording->finish();
    fmt::print("recorded {} steps to {}\n", recording->steps(), a.record);
  }
  return 0;
}

int replay(const TouchArgs& a, const std::string& version, bool sceneOptionsGiven) {
  if (!a.record.empty() || !a.script.empty() || !a.weart.empty() || !a.osc.empty() || !a.forces.empty())
    throw Error("touch: --replay cannot be combined with --record, --script, --weart, --osc or --forces");
  if (sceneOptionsGiven)
    fmt::print(stderr,
               "note: --replay rebuilds the scene from the recording's settings; MESH and scene options "
               "given here are ignored\n");
  SessionRecording recording = SessionRecording::load(a.replay);
  const RecordedSettings r(recording, a.replay);
  if (r.text("tool") != kRecordingTool)
    throw Error(fmt::format("{}: not a recording of `vrdeform touch` (tool '{}')", a.replay, r.text("tool")));
  Scene s;
  s.mesh = r.text("mesh");
  s.scale = r.real("scale");
  s.tets = r.integer("tets");
  s.youngs = r.real("youngs");
  s.poisson = r.real("poisson");
  s.density = r.real("density");
  s.damping = r.real("damping");
  s.rate = r.integer("rate");
  s.substeps = r.integer("substeps");
  s.iterations = r.integer("iterations");
  s.linearDamping = r.real("damping-linear");
  s.hand = r.text("hand");
  s.contact = r.text("contact");
  s.grasp = r.text("grasp");
  s.calibrate = r.text("calibrate") == "1";
  s.alpha = r.real("alpha");
  s.betaContact = r.real("beta-contact");
  s.maxChange = r.real("max-change");
  s.settle = r.real("settle");
  const Taus tau{r.real("tau-contact"), r.real("tau-finger-contact"), r.real("tau-volume"), r.real("tau-strain")};
  std::string expectedHash = r.text("mesh-hash");
  try {
    validate(s);
  } catch (const Error& e) {
    throw Error(fmt::format("{}: bad setting: {}", a.replay, e.what()));
  }
  if (r.text("version") != version)
    fmt::print(stderr, "note: recorded with {}, replaying with {}\n", r.text("version"), version);
  fmt::print("replay: {} ({} steps, {}, input: {})\n", a.replay, recording.steps.size(), r.text("version"),
             r.text("input"));

  Setup body = buildBody(s, true);
  if (fmt::format("{:016x}", body.hash) != expectedHash)
    throw Error(fmt::format("{}: the mesh differs from the one recorded (fingerprint {:016x}, recorded {})", s.mesh,
                            body.hash, expectedHash));
  HapticSessionSettings settings;
  try {
    settings = sessionSettings(s, tau);
  } catch (const Error& e) {
    throw Error(fmt::format("{}: bad setting: {}", a.replay, e.what()));
  }
  printScene(s, settings);
  printTaus(tau, s, s.calibrate ? "calibrated when recorded" : "default scales, as recorded");

  const std::size_t recorded = recording.steps.size();
  RecordingInput input(std::move(recording));
  const std::vector<RecordedStep>& steps = input.recording().steps;
  HapticSession session(*body.world, settings, input.frame(0, 0.0));
  std::optional<AtomicFile> csv;
  if (!a.csv.empty()) csv.emplace(a.csv);
  std::string difference;
  const Tally tally = drive(session, input, stepCap(a.seconds, s.rate), a.reportEvery, nullptr,
                            csv ? &csv->stream() : nullptr, [&](std::uint64_t k) {
                              difference = replayDifference(k, steps[k].outputs, recordedOutputs(session.haptics()));
                              return difference.empty();
                            });
  printSummary(tally, session.rig(), 1.0 / s.rate);
  if (csv) {
    csv->commit();
    fmt::print("wrote {}\n", a.csv);
  }
  if (!difference.empty()) {
    fmt::print("replay: {}\n", difference);
    return 1;
  }
  if (tally.steps == recorded)
    fmt::print("replay: {} steps, identical\n", tally.steps);
  else
    fmt::print("replay: {} steps, identical (the first {} of {})\n", tally.steps, tally.steps, recorded);
  return 0;
}

}  // namespace

std::function<int()> addTouchCommand(CLI::App& app) {
  auto args = std::make_shared<TouchArgs>();
  Scene& s = args->scene;
  CLI::App* cmd = app.add_subcommand(
      "touch", "Poke or grasp a mesh with a scripted hand; print the haptic force; record and replay sessions");
  std::vector<CLI::Option*> sceneOptions;
  const auto scene = [&](CLI::Option* o) {
    sceneOptions.push_back(o);
    return o;
  };
  scene(cmd->add_option(
      "mesh", s.mesh,
      "Surface (.obj .off .stl .ply; tetrahedralised) or tet mesh (.node .ele .mesh .msh .vtk .vtu); not with "
      "--replay"));
  scene(
      cmd->add_option("--scale", s.scale, "Multiplies the coordinates (0.001 for millimetres)")->capture_default_str());
  scene(cmd->add_option("--tets", s.tets, "Surfaces: approximate tet count of the built-in mesher")
            ->capture_default_str());
  scene(cmd->add_option("--youngs", s.youngs, "Young's modulus (Pa)")->capture_default_str());
  scene(cmd->add_option("--poisson", s.poisson, "Poisson ratio, in [0, 0.5)")->capture_default_str());
  scene(cmd->add_option("--density", s.density, "Density (kg/m^3)")->capture_default_str());
  scene(cmd->add_option("--damping", s.damping, "Rayleigh (stiffness-proportional) damping time (s)")
            ->capture_default_str());
  scene(cmd->add_option("--rate", s.rate, "Simulation steps per second")->capture_default_str());
  scene(cmd->add_option("--substeps", s.substeps, "Substeps per step")->capture_default_str());
  scene(cmd->add_option("--iterations", s.iterations, "Gauss-Seidel iterations per substep")->capture_default_str());
  scene(cmd->add_option("--damping-linear", s.linearDamping, "Velocity damping (1/s)")->capture_default_str());
  scene(cmd->add_option("--settle", s.settle, "Seconds the body settles under gravity before the hand appears")
            ->capture_default_str());
  scene(cmd->add_option("--hand", s.hand, "g1 (thumb, index, middle) or pro (five fingers)")->capture_default_str());
  scene(cmd->add_option("--contact", s.contact, "particles or triangles: what the fingertips touch")
            ->capture_default_str());
  scene(cmd->add_option("--grasp", s.grasp, "local, paper (eq. 35) or off")->capture_default_str());
  scene(cmd->add_flag("--no-calibrate", args->noCalibrate, "Keep the default haptic scales (tau = 1)"));
  scene(cmd->add_option("--alpha", s.alpha, "Smoothing factor per step (eq. 44), in (0, 1]")->capture_default_str());
  scene(cmd->add_option("--beta-contact", s.betaContact, "Weight of the contact term (eq. 43), in [0, 1]")
            ->capture_default_str());
  scene(cmd->add_option("--max-change", s.maxChange, "Largest change of a force per ms (inf: no limit)")
            ->capture_default_str());
  scene(cmd->add_option("--script", args->script, "Hand script (docs/hand-input.md); default: the standard poke"));
  CLI::Option* seconds =
      cmd->add_option("--seconds", args->seconds, "Stop after this much simulated time (default: when the input ends)");
  cmd->add_option("--report-every", args->reportEvery, "Seconds between timeline rows")->capture_default_str();
  cmd->add_option("--csv", args->csv, "Write every step's outputs to this CSV file");
  cmd->add_option("--forces", args->forces, "Log every step's per-finger forces with timestamps to this CSV file");
  cmd->add_option("--osc", args->osc, "Send every step's forces as OSC over UDP to HOST:PORT (docs/outputs.md)");
  cmd->add_option("--weart", args->weart,
                  "Drive the hand from a WEART glove and send it the forces: the middleware's HOST:PORT "
                  "(default port 13031)")
      ->check(CLI::Validator(weartEndpointError, "HOST[:PORT]"));
  cmd->add_option("--record", args->record, "Save the session (settings, hand and outputs per step)");
  cmd->add_option("--replay", args->replay,
                  "Rebuild the scene of a recording, replay its hand and check the outputs bit for bit");

  CLI::App* root = &app;
  return [args, root, sceneOptions, seconds]() -> int {
    const TouchArgs& a = *args;
    if (seconds->count() > 0 && !positive(a.seconds))
      throw Error(fmt::format("--seconds must be a positive number, got {}", a.seconds));
    if (!positive(a.reportEvery))
      throw Error(fmt::format("--report-every must be a positive number, got {}", a.reportEvery));
    std::string version = root->version();
    if (version.empty()) version = "vrdeform";
    if (!a.replay.empty()) {
      const bool given =
          std::any_of(sceneOptions.begin(), sceneOptions.end(), [](const CLI::Option* o) { return o->count() > 0; });
      return replay(a, version, given);
    }
    return touch(a, version);
  };
}

}  // namespace vrd
