#include "vrdeform/scene/scene_run.h"

#include <fmt/format.h>
#include <fmt/os.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "vrdeform/core/write_file.h"
#include "vrdeform/devices/csv_recorder.h"
#include "vrdeform/error.h"
#include "vrdeform/io/svg_plot.h"
#include "vrdeform/io/vtu_sequence.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;

std::map<std::string, std::size_t> constraintCounts(const std::vector<SceneBody>& bodies) {
  std::map<std::string, std::size_t> n{
      {"distance", 0}, {"volume", 0}, {"strain", 0}, {"bend", 0}, {"shape_matching", 0}};
  for (const SceneBody& b : bodies) {
    n["distance"] += b.model->distance.size();
    n["volume"] += b.model->volume.size();
    n["strain"] += b.model->strain.size();
    n["bend"] += b.model->bend.size();
    n["shape_matching"] += b.model->shapeMatching ? 1 : 0;
  }
  return n;
}

// A plot's series of a run of any length in bounded memory: every stride-th point, the stride
// doubling (every other point kept) whenever kPlotPoints are held. The CSV files have every step.
constexpr std::size_t kPlotPoints = 8192;
struct ThinnedSeries {
  PlotSeries series;
  std::uint64_t seen = 0, stride = 1;

  void add(double x, double y) {
    if (seen++ % stride != 0) return;
    series.x.push_back(x);
    series.y.push_back(y);
    if (series.x.size() < kPlotPoints) return;
    for (std::size_t i = 0; 2 * i < kPlotPoints; ++i) {
      series.x[i] = series.x[2 * i];
      series.y[i] = series.y[2 * i];
    }
    series.x.resize(kPlotPoints / 2);
    series.y.resize(kPlotPoints / 2);
    stride *= 2;
  }
};

// Per-step series for the plots: the force of each finger and of the hand against time, and during
// pokes the poking finger's force against its depth below the target.
struct Traces {
  std::array<ThinnedSeries, kFingerCount> force, indentation;
  ThinnedSeries paper;

  Traces() {
    for (int f = 0; f < kFingerCount; ++f)
      force[f].series.label = indentation[f].series.label = std::string(fingerName(Finger(f)));
    paper.series.label = "hand (Algorithm 2)";
  }
  void add(double t, const HapticFrame& h, const HandRig& rig, const HandAction* poke) {
    paper.add(t, h.paper);
    for (int f = 0; f < kFingerCount; ++f) force[f].add(t, h.fingers[f].force);
    if (!poke) return;
    const float tipLow = rig.target(poke->finger).y() - rig.settings().geometry.fingertipRadius;
    indentation[int(poke->finger)].add(1e3 * std::max(0.0f, poke->target.y() - tipLow),
                                       h.fingers[int(poke->finger)].newtons);
  }
};

// The files of a run with an outDir; each output only exists when it applies.
class RunFiles {
 public:
  RunFiles(const BuiltScene& scene, const fs::path& dir, const std::array<bool, kFingerCount>& fingers)
      : dir_(dir), fingers_(fingers), plots_(scene.spec.output.plots) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw Error(fmt::format("{}: cannot create the folder: {}", dir.string(), ec.message()));
    forces_.emplace(dir / "forces.csv", fingers);
    stageCsv_.emplace(fmt::output_file((dir / "stage_times.csv").string()));
    stageCsv_->print("step,time_s,phase");
    for (std::size_t s = 0; s < kStageCount; ++s) stageCsv_->print(",{}_ms", stageName(Stage(s)));
    stageCsv_->print(",total_ms\n");
    const double every = scene.spec.output.meshEvery;
    if (every > 0.0) {
      fs::create_directories(dir / "meshes", ec);
      if (ec) throw Error(fmt::format("{}: cannot create the folder: {}", (dir / "meshes").string(), ec.message()));
      meshEvery_ = std::max<std::uint64_t>(1, std::uint64_t(std::llround(every / scene.spec.solver.timeStep)));
      // Each body (tets, or a cloth's triangles), and a render mesh driven by a body's tets.
      const auto add = [&](const SceneBody& b, std::string name, auto mesh, bool render) {
        name += ".pvd";
        meshes_.push_back({&b, render, name, std::make_unique<VtuSequence>(dir / "meshes" / name, std::move(mesh))});
      };
      for (const SceneBody& b : scene.bodies) {
        if (b.kind == BodyKind::Soft)
          add(b, b.name, b.mesh.tets, false);
        else
          add(b, b.name, b.mesh.surface, false);
        if (b.embedding) add(b, b.name + "_render", b.mesh.render, true);
      }
    }
  }

  // One step; `sample` is null in a scene without a hand (the force trace then stays empty).
  void step(const BuiltScene& scene, const HapticSample* sample, const StageTimes& times, std::uint64_t k, double t,
            bool contact) {
    if (sample) forces_->send(*sample);
    stageCsv_->print("{},{:.6f},{}", k, t, contact ? "contact" : "idle");
    for (double ms : times.ms) stageCsv_->print(",{:.5f}", ms);
    stageCsv_->print(",{:.5f}\n", times.totalMs());
    if (meshEvery_ > 0 && (k + 1) % meshEvery_ == 0) {
      for (Meshes& m : meshes_) {
        const Body& b = scene.world->body(m.body->id);
        const std::span<const Point> points(scene.world->particles().x.data() + b.firstParticle, b.particleCount);
        if (m.render) {
          positions_.resize(m.body->embedding->vertexCount());
          m.body->embedding->update(points, std::span<Vec3>(positions_), {});
        } else {
          positions_.resize(points.size());
          for (std::size_t i = 0; i < points.size(); ++i) positions_[i] = points[i].pos;
        }
        m.sequence->addFrame(t, positions_);
      }
    }
  }

  // Everything but summary.json; the plots from the per-step traces.
  void finish(const RunSummary& summary, const Traces& traces, std::vector<fs::path>& files) {
    forces_.reset();  // flushes and closes
    files.push_back("forces.csv");
    stageCsv_->close();
    files.push_back("stage_times.csv");
    writeFile(dir_ / "latency.csv", latencyCsv(summary.latency));
    files.push_back("latency.csv");
    for (const Meshes& m : meshes_) files.push_back(fs::path("meshes") / m.file);
    if (!plots_) return;

    Plot overTime{fmt::format("{}: haptic force", summary.scene), "time (s)", "force (normalised)", {}, {{0.0, 1.0}}};
    for (int f = 0; f < kFingerCount; ++f)
      if (fingers_[f]) overTime.series.push_back(traces.force[f].series);
    overTime.series.push_back(traces.paper.series);
    writeSvgPlot(dir_ / "force_time.svg", overTime);
    files.push_back("force_time.svg");

    Plot overDepth{fmt::format("{}: force against indentation (pokes)", summary.scene),
                   "indentation (mm)",
                   "force (N)",
                   {},
                   std::nullopt};
    for (const ThinnedSeries& s : traces.indentation)
      if (!s.series.x.empty()) overDepth.series.push_back(s.series);
    if (!overDepth.series.empty()) {
      writeSvgPlot(dir_ / "force_indentation.svg", overDepth);
      files.push_back("force_indentation.svg");
    }
  }

 private:
  struct Meshes {
    const SceneBody* body;
    bool render;       // the body's render mesh, else the body itself
    std::string file;  // in meshes/
    std::unique_ptr<VtuSequence> sequence;
  };
  fs::path dir_;
  std::array<bool, kFingerCount> fingers_;
  bool plots_;
  std::optional<CsvRecorder> forces_;
  std::optional<fmt::ostream> stageCsv_;  // written as the steps are made
  std::uint64_t meshEvery_ = 0;
  std::vector<Meshes> meshes_;
  std::vector<Vec3> positions_;
};

// A scripted poke's per-step samples, from its start to kPokeTail after its end; summed up and
// let go once complete, so that a long script's pokes do not pile up.
constexpr double kPokeTail = 0.3;
struct PokeTrace {
  const HandAction* poke;
  std::vector<double> depth, newtons, force;
  std::size_t holdBegin = 0, holdEnd = 0;
  bool done = false;

  // Step k began at time t (the hand's schedule); its frame is done.
  void add(double t, const HapticFrame& h, const HandRig& rig) {
    if (t < poke->start || t >= poke->end() + kPokeTail) return;
    const double hold = poke->start + poke->approach;
    if (t < hold) holdBegin = depth.size() + 1;
    if (t < hold + poke->hold) holdEnd = depth.size() + 1;
    const float tipLow = rig.target(poke->finger).y() - rig.settings().geometry.fingertipRadius;
    depth.push_back(poke->target.y() - tipLow);
    newtons.push_back(h.fingers[int(poke->finger)].newtons);
    force.push_back(h.fingers[int(poke->finger)].force);
  }
  bool complete(double dt) const {
    return double(depth.size()) * dt >= poke->end() + kPokeTail - poke->start - 0.5 * dt;
  }
  PokeSignal signal() const {
    return {poke->finger, poke->start, signalQuality(depth, newtons, holdBegin, holdEnd),
            signalQuality(depth, force, holdBegin, holdEnd)};
  }
};

}  // namespace

RunSummary runScene(BuiltScene& scene, const RunSettings& settings) {
  World& world = *scene.world;
  RunSummary summary;
  summary.scene = scene.spec.name;
  summary.dt = world.settings().timeStep;
  for (const SceneBody& b : scene.bodies) {
    summary.tets += b.model->tets.size();
    summary.particles += b.model->particleCount();
  }
  summary.constraints = constraintCounts(scene.bodies);
  summary.fingers = scene.spec.hand.enabled ? scene.session.hand.fingers : std::array<bool, kFingerCount>{};

  std::unique_ptr<RunFiles> files;
  Traces traces;
  std::array<double, kStageCount> residualRmsSum{};
  std::array<std::size_t, kStageCount> residualSteps{};
  double iterations = 0.0, coldSubsteps = 0.0;
  // The scripted pokes by start (they do not overlap); those before firstOpen are done.
  std::vector<PokeTrace> pokes;
  for (const HandAction& a : scene.actions)
    if (a.kind == ActionKind::Poke) pokes.push_back(PokeTrace{&a, {}, {}, {}});
  std::stable_sort(pokes.begin(), pokes.end(),
                   [](const PokeTrace& a, const PokeTrace& b) { return a.poke->start < b.poke->start; });
  std::size_t firstOpen = 0;
  // The scripted grasps, each with the steps it held the body while its time ran.
  std::vector<std::pair<const HandAction*, std::uint64_t>> grasps;
  for (const HandAction& a : scene.actions)
    if (a.kind == ActionKind::Grasp) grasps.push_back({&a, 0});
  constexpr std::size_t kEventsListed = 100;  // in summary.events; nanEvents counts them all
  for (const SimEvent& e : scene.settleEvents)
    if (++summary.nanEvents <= kEventsListed)
      summary.events.push_back(fmt::format("settling, step {}: {}", e.step, e.message));

  HandInput* input = settings.input ? settings.input : scene.input.get();
  std::optional<HapticSession> session;
  if (scene.spec.hand.enabled) session.emplace(world, scene.session, input ? input->frame(0, 0.0) : HandFrame{});
  const auto start = std::chrono::steady_clock::now();
  try {
    if (!settings.outDir.empty()) files = std::make_unique<RunFiles>(scene, settings.outDir, summary.fingers);
    for (std::uint64_t k = 0; k < settings.steps; ++k) {
      const double t = double(k + 1) * summary.dt;
      bool contact = false;
      if (session) {
        const HandFrame frame = input ? input->frame(k, double(k) * summary.dt) : HandFrame{};
        session->step(frame);
        if (settings.record) settings.record({frame, recordedOutputs(session->haptics())});
        contact = session->inContact();
      } else {
        world.step();
      }
      const StageTimes& times = session ? session->times() : world.lastStep().times;
      iterations += world.lastStep().iterations;
      coldSubsteps += world.lastStep().coldSubsteps;
      if (contact) summary.coldSubstepsTouching += std::uint64_t(world.lastStep().coldSubsteps);
      for (std::size_t s = 0; s < kStageCount; ++s)
        if (const Residual& r = world.lastStep().residuals[s]; std::isfinite(r.max)) {
          residualRmsSum[s] += r.rms;
          ++residualSteps[s];
          summary.residuals[s].max =
              std::max(std::isfinite(summary.residuals[s].max) ? summary.residuals[s].max : 0.0, r.max);
        }
      summary.latency.add(times, contact);
      for (const SimEvent& e : world.takeEvents())
        if (++summary.nanEvents <= kEventsListed)
          summary.events.push_back(fmt::format("step {}: {}", e.step, e.message));
      double loss = 0.0;
      for (const SceneBody& b : scene.bodies)
        if (b.kind == BodyKind::Soft) loss = std::max(loss, std::abs(world.volumeLoss(b.id)));
      summary.volumeLossMax = std::max(summary.volumeLossMax, loss);
      summary.volumeLossFinal = loss;
      summary.bodyContactsMax = std::max(summary.bodyContactsMax, world.lastStep().bodyContacts);
      summary.penetrationMax = std::max(summary.penetrationMax, world.lastStep().deepestPenetration);
      summary.steps = k + 1;

      std::optional<HapticSample> sample;
      if (session) {
        const HapticFrame& h = session->haptics();
        sample = sampleOf(k + 1, *session);
        for (HapticOutput* out : settings.outputs) out->send(*sample);
        summary.paperMax = std::max(summary.paperMax, h.paper);
        for (int f = 0; f < kFingerCount; ++f) {
          summary.forceMax[f] = std::max(summary.forceMax[f], h.fingers[f].force);
          summary.newtonsMax[f] = std::max(summary.newtonsMax[f], h.fingers[f].newtons);
        }
        // Indentation only for the scene's own pokes (a glove's hand has no target). Step k
        // began at k dt, the hand's time for it.
        const double began = double(k) * summary.dt;
        const HandAction* poking = nullptr;
        if (input == scene.input.get())
          for (std::size_t j = firstOpen; j < pokes.size() && pokes[j].poke->start <= began; ++j) {
            PokeTrace& p = pokes[j];
            if (p.done) continue;
            if (began < p.poke->end()) poking = p.poke;
            p.add(began, h, session->rig());
            if (p.complete(summary.dt) || began >= p.poke->end() + kPokeTail) {
              if (p.complete(summary.dt)) summary.pokes.push_back(p.signal());
              p = PokeTrace{p.poke, {}, {}, {}, 0, 0, true};
            }
          }
        while (firstOpen < pokes.size() && pokes[firstOpen].done) ++firstOpen;
        if (input == scene.input.get() && session->grasp().active())
          for (auto& [grasp, held] : grasps) held += began >= grasp->start && began < grasp->end();
        traces.add(t, h, session->rig(), poking);
      }
      if (files) files->step(scene, sample ? &*sample : nullptr, times, k, t, contact);
      if (settings.afterStep &&
          !settings.afterStep(RunStep{k, t, session ? &*session : nullptr, &times, loss, summary.nanEvents}))
        break;
    }
    summary.ok = true;
  } catch (const std::exception& e) {
    summary.error = e.what();
  }
  for (HapticOutput* out : settings.outputs) out->release();
  if (input == scene.input.get())
    for (const auto& [grasp, held] : grasps)
      if (grasp->end() <= double(summary.steps) * summary.dt + 1e-9)
        summary.grasps.push_back({grasp->finger, grasp->start, grasp->end() - grasp->start, double(held) * summary.dt});
  for (std::size_t s = 0; s < kStageCount; ++s)
    if (residualSteps[s] > 0) summary.residuals[s].rms = residualRmsSum[s] / double(residualSteps[s]);
  if (summary.steps > 0) {
    summary.iterationsMean = iterations / double(summary.steps);
    summary.coldSubstepShare = coldSubsteps / (double(summary.steps) * scene.spec.solver.substeps);
  }
  summary.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (files && summary.ok) {
    try {
      files->finish(summary, traces, summary.files);
    } catch (const std::exception& e) {
      summary.ok = false;
      summary.error = e.what();
    }
  }
  if (!settings.outDir.empty()) {
    std::error_code ec;
    fs::create_directories(settings.outDir, ec);  // a failed run may not have made it
    writeFile(settings.outDir / "summary.json", summaryJson(summary));
    summary.files.push_back("summary.json");
  }
  if (!summary.ok) throw Error(summary.error);
  return summary;
}

std::string summaryJson(const RunSummary& s) {
  using nlohmann::json;
  // JSON has no NaN: a value that is not finite (no frames in a phase) becomes null.
  const auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  json j;
  j["scene"] = s.scene;
  j["ok"] = s.ok;
  if (!s.ok) j["error"] = s.error;
  j["steps"] = s.steps;
  j["dt"] = s.dt;
  j["tets"] = s.tets;
  j["particles"] = s.particles;
  j["constraints"] = s.constraints;
  j["volume_loss_max"] = number(s.volumeLossMax);
  j["volume_loss_final"] = number(s.volumeLossFinal);
  j["body_contacts_max"] = s.bodyContactsMax;
  j["penetration_max_m"] = number(s.penetrationMax);
  json forceMax = json::object(), newtonsMax = json::object();
  for (int f = 0; f < kFingerCount; ++f)
    if (s.fingers[f]) {
      forceMax[std::string(fingerName(Finger(f)))] = number(s.forceMax[f]);
      newtonsMax[std::string(fingerName(Finger(f)))] = number(s.newtonsMax[f]);
    }
  j["force_max"] = forceMax;
  j["newtons_max"] = newtonsMax;
  j["paper_force_max"] = number(s.paperMax);
  const auto quality = [&](const SignalQuality& q) {
    return json{{"roughness", number(q.roughness)},
                {"loading_spearman", number(q.loadingSpearman)},
                {"hold_noise", number(q.holdNoise)},
                {"lag_steps", q.lagSteps},
                {"peak", number(q.peak)}};
  };
  json pokes = json::array();
  for (const PokeSignal& p : s.pokes)
    pokes.push_back({{"finger", std::string(fingerName(p.finger))},
                     {"start", p.start},
                     {"newtons", quality(p.newtons)},
                     {"force", quality(p.force)}});
  j["pokes"] = pokes;
  json grasps = json::array();
  for (const GraspOutcome& g : s.grasps)
    grasps.push_back({{"finger", std::string(fingerName(g.finger))},
                      {"start", g.start},
                      {"seconds", g.seconds},
                      {"held_seconds", g.heldSeconds}});
  j["grasps"] = grasps;
  json residuals = json::object();
  for (std::size_t k = 0; k < kStageCount; ++k)
    if (std::isfinite(s.residuals[k].max))
      residuals[std::string(stageName(Stage(k)))] = {{"rms_mean", number(s.residuals[k].rms)},
                                                     {"max", number(s.residuals[k].max)}};
  j["residuals"] = residuals;
  j["iterations_mean"] = number(s.iterationsMean);
  j["cold_substep_share"] = number(s.coldSubstepShare);
  j["cold_substeps_touching"] = s.coldSubstepsTouching;
  json stages = json::object();
  const auto stats = [&](const SampleStats& st) {
    return json{{"mean", number(st.mean)}, {"p50", number(st.median)}, {"p95", number(st.p95)},
                {"p99", number(st.p99)},   {"std", number(st.stddev)}, {"max", number(st.max)}};
  };
  for (std::size_t k = 0; k < kStageCount; ++k) {
    const SampleStats st = s.latency.stage(Stage(k), Phase::All);
    if (st.count > 0 && st.max > 0.0) stages[std::string(stageName(Stage(k)))] = stats(st);
  }
  stages["total"] = stats(s.latency.total(Phase::All));
  j["stage_ms"] = stages;
  j["frames"] = {{"idle", s.latency.frames(Phase::Idle)}, {"contact", s.latency.frames(Phase::Contact)}};
  j["nan_events"] = s.nanEvents;
  j["events"] = s.events;
  j["wall_seconds"] = s.wallSeconds;
  json files = json::array();
  for (const auto& f : s.files) files.push_back(f.generic_string());
  j["files"] = files;
  return j.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
}

}  // namespace vrd
