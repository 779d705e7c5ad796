#include "scene_runner.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string_view>

#include "build_observer.h"
#include "vrdeform/core/write_file.h"
#include "vrdeform/devices/csv_recorder.h"
#include "vrdeform/devices/glove_link.h"
#include "vrdeform/devices/osc_output.h"
#include "vrdeform/devices/stop_signals.h"
#include "vrdeform/error.h"
#include "vrdeform/scene/scene_run.h"

namespace vrd {
namespace {

std::string fingerList(const std::array<bool, kFingerCount>& fingers) {
  std::string s;
  for (int f = 0; f < kFingerCount; ++f)
    if (fingers[f]) s += fmt::format("{}{}", s.empty() ? "" : ", ", fingerName(Finger(f)));
  return s;
}

// `handFrom`: what moves the hand instead of the scene's scripted actions (a glove, a recording),
// or empty.
void printScene(const BuiltScene& scene, std::string_view handFrom) {
  const SceneSpec& s = scene.spec;
  for (const SceneBody& b : scene.bodies) {
    double mass = 0.0;
    for (float w : b.model->invMass)
      if (w > 0.0f) mass += 1.0 / w;
    const Eigen::AlignedBox3f box = bodyBounds(*scene.world, b.id);
    const Vec3 lo = box.min(), hi = box.max();
    fmt::print("body '{}': {} particles, {} tets, {} triangles, {:.3f} kg{}\n", b.name, b.model->particleCount(),
               b.model->tets.size(), b.model->triangles.size(), mass,
               b.embedding ? fmt::format(", render mesh of {} vertices", b.embedding->vertexCount()) : "");
    fmt::print(
        "  settled in x [{:.3f}, {:.3f}], y [{:.3f}, {:.3f}], z [{:.3f}, {:.3f}] m; top at ({:.3f}, {:.3f}, {:.3f})\n",
        lo.x(), hi.x(), lo.y(), hi.y(), lo.z(), hi.z(), b.top.x(), b.top.y(), b.top.z());
  }
  fmt::print("solver: dt = {:.6g} s ({:g} Hz), {} substep(s) x {} iteration(s)\n", s.solver.timeStep,
             1.0 / s.solver.timeStep, s.solver.substeps, s.solver.iterations);
  if (!s.hand.enabled) return;
  fmt::print("hand: {} ({}), fingertip radius {:g} mm, contact against {}, grasp {}\n",
             s.hand.rig.fingers[3] ? "Pro" : "G1", fingerList(s.hand.rig.fingers),
             1e3f * s.hand.rig.geometry.fingertipRadius,
             s.hand.rig.contact == FingertipContactMode::Triangles ? "triangles" : "particles",
             !s.hand.grasp.enabled                   ? "off"
             : s.hand.grasp.mode == GraspMode::Paper ? "paper"
                                                     : "local");
  if (!handFrom.empty()) {
    fmt::print("  moved by {}: the scene's scripted actions do not run\n", handFrom);
    return;
  }
  for (const HandAction& a : scene.actions)
    fmt::print("  {} with the {} at {:.1f}-{:.1f} s on ({:.3f}, {:.3f}, {:.3f}) m\n",
               a.kind == ActionKind::Poke ? "poke" : "grasp", fingerName(a.finger), a.start, a.end(), a.target.x(),
               a.target.y(), a.target.z());
}

// One summary line per stage like the paper's Table 1 (constraint stages) and the latency table.
void printSummary(const RunSummary& r, const BuiltScene& scene) {
  const double simulated = double(r.steps) * r.dt;
  fmt::print("\nsummary: {} steps ({:.3f} s simulated) in {:.3f} s wall time ({:.1f}x real time)\n", r.steps, simulated,
             r.wallSeconds, r.wallSeconds > 0 ? simulated / r.wallSeconds : 0.0);
  fmt::print("  tets {}, particles {}, constraints:", r.tets, r.particles);
  for (const auto& [type, n] : r.constraints)
    if (n > 0) fmt::print(" {} {}", type, n);
  fmt::print("\n  volume loss: max {:.3f}%, final {:.3f}%\n", 100 * r.volumeLossMax, 100 * r.volumeLossFinal);
  if (r.bodyContactsMax > 0)
    fmt::print("  body contact: up to {} contacts pushing, deepest penetration {:.2f} mm\n", r.bodyContactsMax,
               1e3 * r.penetrationMax);
  if (scene.spec.hand.enabled) {
    fmt::print("  force max (normalised, newtons):");
    for (int f = 0; f < kFingerCount; ++f)
      if (r.fingers[f]) fmt::print(" {} {:.3f} ({:.3f} N);", fingerName(Finger(f)), r.forceMax[f], r.newtonsMax[f]);
    fmt::print(" hand (Algorithm 2) {:.3f}\n", r.paperMax);
    for (const PokeSignal& p : r.pokes)
      if (!(p.newtons.peak > 0.0))
        fmt::print(
            "  poke at {:.2f} s ({}): never touched the body (nothing was under the fingertip while it pressed: aim it "
            "with `offset`, or give a body that is still moving more `settle`)\n",
            p.start, fingerName(p.finger));
      else
        for (const auto& [channel, q, unit] :
             {std::tuple{"N", &p.newtons, " N"}, std::tuple{"normalised", &p.force, ""}})
          fmt::print(
              "  poke at {:.2f} s ({}, {}): roughness {:.2f}, loading Spearman {:.3f}, hold noise {:.1f}%, lag {} "
              "steps, peak {:.3f}{}\n",
              p.start, fingerName(p.finger), channel, q->roughness, q->loadingSpearman, 100 * q->holdNoise, q->lagSteps,
              q->peak, unit);
    for (const GraspOutcome& g : r.grasps)
      if (g.heldSeconds > 0.0)
        fmt::print("  grasp at {:.2f} s (thumb and {}): held {:.2f} s of its {:.2f}\n", g.start, fingerName(g.finger),
                   g.heldSeconds, g.seconds);
      else
        fmt::print(
            "  grasp at {:.2f} s (thumb and {}): never took hold (the two fingertips never pushed the body at once "
            "while closing: aim it where both reach the body, or give it more `depth`)\n",
            g.start, fingerName(g.finger));
  }
  fmt::print(
      "  convergence (the last iteration's corrections / mean rest edge; RMS mean, max), {:.1f} iterations "
      "a step:",
      r.iterationsMean);
  for (std::size_t s = 0; s < kStageCount; ++s)
    if (std::isfinite(r.residuals[s].max))
      fmt::print(" {} {:.1e} {:.1e};", stageName(Stage(s)), r.residuals[s].rms, r.residuals[s].max);
  fmt::print("\n");
  if (r.coldSubstepShare >= 0.001 || r.coldSubstepsTouching > 0)
    fmt::print(
        "  warm start: {:.1f}% of the substeps started cold (their warm start would have moved a particle over a "
        "quarter of its body's mean rest edge), {} of them while a fingertip touched a body (where the force can "
        "dip: more substeps remove them){}\n",
        100 * r.coldSubstepShare, r.coldSubstepsTouching,
        r.coldSubstepShare > 0.02 ? ": give the scene more substeps" : "");
  fmt::print("  NaN events: {}\n", r.nanEvents);
  for (const std::string& e : r.events) fmt::print("    {}\n", e);
  const auto mean = [&](Stage s) { return r.latency.stage(s, Phase::All).mean; };
  const double tv = mean(Stage::Volume), ts = mean(Stage::Strain), tm = mean(Stage::ShapeMatching);
  const double tvs = mean(Stage::StrainVolume), tc = mean(Stage::Distance), tb = mean(Stage::Bend);
  if (r.tets > 0 && tvs > 0)
    fmt::print(
        "\nconstraints per frame (paper Table 1): T_v+T_s {:.4f} ms (one pass), T_m {:.4f} ms, T_total {:.4f} ms\n",
        tvs, tm, tvs + tm);
  else if (r.tets > 0)
    fmt::print(
        "\nconstraints per frame (paper Table 1): T_v {:.4f} ms, T_s {:.4f} ms, T_m {:.4f} ms, T_total {:.4f} ms\n", tv,
        ts, tm, tv + ts + tm);
  else
    fmt::print("\nconstraints per frame (paper Table 2): T_c {:.4f} ms, T_b {:.4f} ms, T_total {:.4f} ms\n", tc, tb,
               tc + tb);
  fmt::print("\nper-stage latency (paper Table 3), ms per step:\n{}", latencyTable(r.latency));
}

// The run's timeline: every finger of the hand, normalised and in newtons, each report interval
// (a bar on a terminal instead).
class Progress {
 public:
  Progress(double seconds, double reportEvery, double dt, const HandSpec& hand)
      : seconds_(seconds),
        tty_(::isatty(STDOUT_FILENO) == 1),
        every_(std::max<std::uint64_t>(1, std::llround(reportEvery / dt))),
        hand_(hand.enabled) {
    for (int f = 0; f < kFingerCount; ++f)
      if (hand.rig.fingers[std::size_t(f)]) fingers_.push_back(Finger(f));
    if (tty_) return;
    std::string header = fmt::format("{:>8}", "t (s)");
    for (const Finger f : fingers_)
      header += fmt::format(" {:>8} {:>10}", fingerName(f), fmt::format("{} (N)", fingerName(f)));
    fmt::print("{} {:>8} {:>8} {:>6} {:>10}\n", header, "hand", "contacts", "grasp", "vol. loss");
  }
  void step(const RunStep& s) {
    if (tty_) {
      const int width = 40;
      const double done = std::clamp(s.time / seconds_, 0.0, 1.0);
      const int filled = int(done * width);
      if (s.step % 8 == 0 || done >= 1.0)
        fmt::print("\r  [{}{}] {:3.0f}%  {:.2f} / {:.2f} s ", std::string(filled, '#'),
                   std::string(width - filled, ' '), 100 * done, s.time, seconds_);
      std::fflush(stdout);
      return;
    }
    if ((s.step + 1) % every_ != 0) return;
    std::string line = fmt::format("{:8.3f}", s.time);
    if (!hand_ || !s.session) {
      for (std::size_t k = 0; k < fingers_.size(); ++k) line += fmt::format(" {:>8} {:>10}", "-", "-");
      fmt::print("{} {:>8} {:>8} {:>6} {:9.3f}%\n", line, "-", "-", "-", 100 * s.volumeLoss);
      return;
    }
    const HapticFrame& h = s.session->haptics();
    std::size_t contacts = 0;
    for (const FingerHaptics& f : h.fingers) contacts += f.contacts;
    for (const Finger f : fingers_) {
      const FingerHaptics& finger = h.fingers[int(f)];
      line += fmt::format(" {:8.3f} {:10.4f}", finger.force, finger.newtons);
    }
    fmt::print("{} {:8.3f} {:8} {:>6} {:9.3f}%\n", line, h.paper, contacts, s.session->grasp().active() ? "on" : "off",
               100 * s.volumeLoss);
  }
  void finish() {
    if (tty_) fmt::print("\n");
  }

 private:
  double seconds_;
  bool tty_;
  std::uint64_t every_;
  bool hand_;
  std::vector<Finger> fingers_;
};

std::string meshHashKey(std::size_t body) { return fmt::format("mesh-hash.{}", body + 1); }

}  // namespace

void addRunOptions(CLI::App& command, RunOptions& o) {
  auto* seconds = command.add_option("--seconds", o.seconds, "Simulated time after settling (default: the scene's)")
                      ->check(CLI::Range(1e-6, 1e9));
  command.add_option("--steps", o.steps, "Number of steps instead of --seconds")
      ->check(CLI::Range(std::uint64_t(1), std::uint64_t(1e12)))
      ->excludes(seconds);
  command.add_option("--out", o.out,
                     "Write summary.json, forces.csv, stage_times.csv, latency.csv, meshes/*.pvd and plots here");
  command.add_option("--report-every", o.reportEvery, "Seconds between timeline rows (when not on a terminal)")
      ->check(CLI::Range(1e-6, 1e9))
      ->capture_default_str();
  command
      .add_option("--weart", o.weart,
                  "Drive the hand from a WEART glove and send it the forces, in real time: HOST[:PORT] of the "
                  "middleware (default port 13031)")
      ->check(CLI::Validator(weartEndpointError, "HOST[:PORT]"));
  command.add_option("--forces", o.forces,
                     "Log every step (forces, indentation, fingertips: docs/outputs.md) to this CSV file");
  command.add_option("--osc", o.osc, "Send every step's forces as OSC over UDP to HOST:PORT (docs/outputs.md)");
  command.add_option("--record", o.record,
                     "Record the hand of every step and its outputs into this file as the run goes "
                     "(docs/hand-input.md)");
  command.add_option("--replay", o.replay,
                     "Run a recording's scene again with its recorded hand and check every step's outputs bit "
                     "for bit");
  command.add_flag(
      "--render", o.render,
      "Also draw the run headless into --out: frames/frame_NNNNN.png, and video.mp4 when ffmpeg is on PATH");
  addVideoOptions(command, o.video);
}

std::optional<SessionRecording> loadReplay(const RunOptions& o, std::string_view tool) {
  if (o.replay.empty()) return std::nullopt;
  if (!o.record.empty() || !o.weart.empty()) throw Error("--replay cannot go with --record or --weart");
  SessionRecording recording = SessionRecording::load(o.replay);
  const std::string* recordedBy = recording.setting("tool");
  if (!recordedBy || *recordedBy != tool)
    throw Error(fmt::format("{}: not a recording of `vrdeform {}`{}", o.replay, tool,
                            recordedBy ? fmt::format(" (it is one of `vrdeform {}`)", *recordedBy) : ""));
  return recording;
}

int runSceneCommand(const SceneSpec& spec, const RunOptions& a,
                    std::vector<std::pair<std::string, std::string>> recorded,
                    std::optional<SessionRecording> replaying) {
  if (a.render && a.out.empty()) throw Error("--render needs --out DIR for the frames");
  if ((replaying || !a.record.empty()) && !spec.hand.enabled)
    throw Error(fmt::format("scene {} has no hand to record or replay", spec.name));
  if (!a.out.empty()) prepareOutputFolder(a.out);
  printSceneTitle(spec);
  fmt::print("  from {}\n", spec.source);
  const StopSignals signals;  // from here on Ctrl-C stops what runs: meshing, settling, calibrating, the run
  BuiltScene scene = buildScene(spec, commandObserver(signals));
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    const std::string hash = fmt::format("{:016x}", scene.bodies[b].mesh.hash);
    if (const std::string* was = replaying ? replaying->setting(meshHashKey(b)) : nullptr; was && *was != hash)
      throw Error(fmt::format("{}: the mesh differs from the one recorded (fingerprint {}, recorded {})",
                              spec.bodies[b].mesh, hash, *was));
    recorded.emplace_back(meshHashKey(b), hash);
  }
  printScene(scene, !a.weart.empty() ? fmt::format("the WEART glove at {}", a.weart)
                    : replaying      ? fmt::format("the recording {}", a.replay)
                                     : std::string());

  const double dt = spec.solver.timeStep;
  std::optional<GloveLink> glove;
  if (!a.weart.empty()) {
    if (!spec.hand.enabled) throw Error(fmt::format("scene {} has no hand for the glove to drive", spec.name));
    const Vec3 point = scene.actions.empty() ? scene.bodies.front().top : scene.actions.front().target;
    glove.emplace(a.weart, scene.session.hand, point);
  }
  std::uint64_t steps = replaying ? std::max<std::uint64_t>(1, replaying->steps.size()) : a.steps;
  if (steps == 0) {
    const double seconds = a.seconds > 0.0 ? a.seconds : glove ? 1e9 : spec.seconds;
    steps = std::max<std::uint64_t>(1, std::uint64_t(std::min(std::round(seconds / dt), 1e15)));
  }
  const double seconds = double(steps) * dt;
  fmt::print("running {} steps ({:g} s){}\n\n", steps, seconds, glove ? " in real time" : "");

  RunSettings settings;
  settings.steps = steps;
  settings.outDir = a.out;
  std::vector<std::unique_ptr<HapticOutput>> outputs;
  if (!a.forces.empty()) outputs.push_back(std::make_unique<CsvRecorder>(a.forces, scene.session.hand.fingers));
  if (!a.osc.empty()) {
    const HostPort to = parseHostPort(a.osc);
    outputs.push_back(std::make_unique<OscOutput>(to.host, to.port));
  }
  for (const auto& o : outputs) settings.outputs.push_back(o.get());
  if (glove) settings.input = &glove->input();
  // --record: every step's hand and outputs, written as the run goes; --replay: the recorded hand,
  // each step's outputs checked against the recorded ones bit for bit.
  std::optional<SessionRecordingWriter> recorder;
  if (!a.record.empty()) {
    recorder.emplace(a.record, recorded);
    settings.record = [&](const RecordedStep& step) { recorder->add(step); };
  }
  std::optional<RecordingInput> replayInput;
  std::string difference;
  std::uint64_t replayed = 0;
  if (replaying) {
    replayInput.emplace(std::move(*replaying));
    settings.input = &*replayInput;
    settings.record = [&](const RecordedStep& step) {
      const std::vector<RecordedStep>& steps = replayInput->recording().steps;
      if (difference.empty() && replayed < steps.size())
        difference = replayDifference(replayed, steps[replayed].outputs, step.outputs);
      ++replayed;
    };
  }
  std::optional<SceneVideo> video;
  if (a.render) {
    try {
      video.emplace(scene, a.out, a.video);
    } catch (const Error& e) {
      fmt::print(stderr, "vrdeform: cannot render: {}\n", e.what());
      return 1;
    }
  }
  Progress progress(seconds, a.reportEvery, dt, spec.hand);
  settings.afterStep = [&](const RunStep& s) {
    progress.step(s);
    if (video) video->afterStep(s);
    if (glove && s.session) glove->afterStep(s.session->haptics(), s.time);
    return !signals.requested() && difference.empty();
  };
  RunSummary summary;
  try {
    summary = runScene(scene, settings);
  } catch (const Error& e) {
    progress.finish();
    if (glove) glove->shutdown();
    fmt::print(stderr, "vrdeform: the run failed: {}\n", e.what());
    if (!a.out.empty()) fmt::print(stderr, "  {}/summary.json says what ran before\n", a.out);
    return 1;
  }
  progress.finish();
  if (glove) glove->shutdown();
  if (signals.requested()) fmt::print("stopped by a signal after {} steps\n", summary.steps);
  printSummary(summary, scene);
  if (video)
    for (const auto& f : video->finish()) summary.files.push_back(f);
  if (!summary.files.empty()) {
    fmt::print("\nwrote into {}:", a.out);
    for (const auto& f : summary.files) fmt::print(" {}", f.generic_string());
    fmt::print("\n");
  }
  if (!a.forces.empty()) fmt::print("wrote {}\n", a.forces);
  if (recorder) {
    recorder->finish();
    fmt::print("recorded {} steps into {}\n", recorder->steps(), a.record);
  }
  if (!difference.empty()) {
    fmt::print("replay: {}\n", difference);
    return 1;
  }
  if (replayInput) fmt::print("replay: {} steps, identical\n", replayed);
  return 0;
}

}  // namespace vrd
