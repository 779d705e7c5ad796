#include "vrdeform/study/study_simulation.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <random>
#include <vector>

#include "vrdeform/core/text_tokens.h"
#include "vrdeform/core/write_file.h"
#include "vrdeform/error.h"
#include "vrdeform/metrics/signal_quality.h"
#include "vrdeform/scene/scene_run.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;

// What a trial's index finger felt during the scene's first scripted poke: the glove's signal
// (the force for condition A, the baseline for B) against the indentation.
struct Felt {
  double roughness = 1.0, spearman = 1.0, peak = 0.0;
};

Felt feltInTrial(const SceneSpec& spec, const std::vector<double>& depth, const std::vector<double>& felt) {
  const double dt = spec.solver.timeStep;
  for (const ActionSpec& a : spec.hand.actions) {
    if (a.action.kind != ActionKind::Poke) continue;
    const std::size_t begin = std::size_t(std::lround(a.action.start / dt));
    const std::size_t end = std::min(depth.size(), std::size_t(std::lround((a.action.end() + 0.3) / dt)));
    if (end <= begin) break;
    const std::size_t n = end - begin;  // signalQuality clamps the hold to a trial cut short
    const std::size_t holdBegin = std::size_t(std::lround((a.action.start + a.action.approach) / dt)) - begin;
    const std::size_t holdEnd = holdBegin + std::size_t(std::lround(a.action.hold / dt));
    const SignalQuality q =
        signalQuality(std::span(depth).subspan(begin, n), std::span(felt).subspan(begin, n), holdBegin, holdEnd);
    Felt f;
    f.peak = q.peak;
    if (std::isfinite(q.roughness)) f.roughness = q.roughness;
    f.spearman = std::isfinite(q.loadingSpearman) ? q.loadingSpearman : 0.0;  // no rise with depth: nothing graded
    return f;
  }
  return {};
}

// The model answer (1..points) for what was felt: a clean, graded signal (roughness 1, loading
// Spearman 1) rates near the top, a stepped or ungraded one near the middle.
double feltScore(const Felt& f, int points) {
  const double q = std::clamp(2.0 - f.roughness, 0.0, 1.0) * std::clamp(f.spearman, 0.0, 1.0);
  return 1.0 + (points - 1) * (0.35 + 0.6 * q);
}

// A seeded normal draw per (participant, condition, item): the same answers however often the
// participant's run is stopped and resumed.
double draw(const SimulatedParticipant& s, std::size_t participant, std::size_t condition, std::size_t item) {
  std::seed_seq seq{std::uint64_t(s.seed), std::uint64_t(participant), std::uint64_t(condition), std::uint64_t(item)};
  std::mt19937_64 rng(seq);
  return std::normal_distribution<double>(0.0, s.noise)(rng);
}

int clampRound(double v, int lo, int hi) { return std::clamp(int(std::lround(v)), lo, hi); }

nlohmann::json runTrial(const StudyCondition& c, const StudyTask& task, int trial, const fs::path& dir,
                        const StudyRunSettings& settings) {
  SceneSpec spec = c.spec;
  spec.output.meshEvery = 0.0;
  spec.output.plots = false;
  SceneBuildObserver observer;
  observer.stop = settings.stop;
  BuiltScene scene = buildScene(spec, observer);
  const double seconds = task.seconds > 0.0 ? task.seconds : spec.seconds;
  RunSettings run;
  run.steps = std::uint64_t(std::lround(seconds / spec.solver.timeStep));
  const fs::path partial = dir.parent_path() / (dir.filename().string() + ".partial");
  std::error_code error;
  fs::remove_all(partial, error);  // what a killed run left
  run.outDir = partial;
  std::vector<double> depth, felt;
  bool stopped = false;
  run.afterStep = [&](const RunStep& s) {
    if (s.session) {  // a scene without a hand: nothing felt
      const FingerHaptics& f = s.session->haptics().fingers[int(Finger::Index)];
      depth.push_back(f.depth);
      felt.push_back(c.force == StudyForce::Baseline ? f.baseline : f.force);
    }
    stopped = settings.stop && settings.stop();
    return !stopped;
  };
  const RunSummary summary = runScene(scene, run);
  if (stopped) {
    fs::remove_all(partial, error);
    throw Stopped(fmt::format("stopped during trial {} of {} in condition {}", trial, task.name, c.name));
  }
  const Felt f = feltInTrial(spec, depth, felt);
  nlohmann::json j{{"condition", c.name},
                   {"task", task.name},
                   {"trial", trial},
                   {"scene", c.scene},
                   {"substeps", spec.solver.substeps},
                   {"iterations", spec.solver.iterations},
                   {"steps", summary.steps},
                   {"felt_roughness", f.roughness},
                   {"felt_spearman", f.spearman},
                   {"felt_peak", f.peak}};
  writeFile(partial / "trial.json", j.dump(2) + "\n");
  fs::rename(partial, dir, error);  // the finished trial appears whole
  if (error)
    throw Error(fmt::format("{}: cannot move the finished trial into place: {}", dir.string(), error.message()));
  return j;
}

// A kept trial's record; anything but what runTrial wrote is refused, naming the folder to delete.
nlohmann::json readTrial(const fs::path& file) {
  nlohmann::json j = nlohmann::json::parse(io::readFileBytes(file), nullptr, false);
  if (!j.is_object() || !j.contains("felt_roughness") || !j["felt_roughness"].is_number() ||
      !j.contains("felt_spearman") || !j["felt_spearman"].is_number())
    throw Error(
        fmt::format("{}: not a finished trial's record; delete its folder to run the trial again", file.string()));
  return j;
}

}  // namespace

StudyRunResult runSimulatedParticipant(const StudySpec& study, const StudyRunSettings& settings) {
  const std::vector<std::size_t> order = study.orderOf(settings.participant);
  const fs::path me = settings.dataDir / fmt::format("P{}", settings.participant);
  prepareOutputFolder(me / "trials");
  StudyRunResult result;
  if (study.practice) {
    const fs::path dir = me / "practice";
    if (fs::is_regular_file(dir / "trial.json")) {
      readTrial(dir / "trial.json");
      ++result.trialsKept;
    } else {
      runTrial(study.practice->condition, study.practice->task, 1, dir, settings);
      ++result.trialsRun;
      if (settings.log) settings.log(fmt::format("P{}: practice", settings.participant));
    }
  }
  std::vector<double> score(study.conditions.size(), 0.0), roughness(score), spearman(score);
  for (std::size_t pos = 0; pos < order.size(); ++pos) {
    const StudyCondition& c = study.conditions[order[pos]];
    double sum = 0.0;
    int count = 0;
    for (std::size_t t = 0; t < study.tasks.size(); ++t)
      for (int r = 1; r <= study.trials; ++r) {
        if (settings.stop && settings.stop()) throw Stopped("stopped between trials");
        const fs::path dir = me / "trials" / fmt::format("{}-{}-{}", pos + 1, t + 1, r);
        nlohmann::json j;
        if (fs::is_regular_file(dir / "trial.json")) {
          j = readTrial(dir / "trial.json");
          ++result.trialsKept;
        } else {
          j = runTrial(c, study.tasks[t], r, dir, settings);
          ++result.trialsRun;
          if (settings.log)
            settings.log(
                fmt::format("P{}: condition {} ({} of {}), {} trial {}: felt roughness {:.2f}, Spearman {:.3f}",
                            settings.participant, c.name, pos + 1, order.size(), study.tasks[t].name, r,
                            j["felt_roughness"].get<double>(), j["felt_spearman"].get<double>()));
        }
        sum += feltScore({j["felt_roughness"].get<double>(), j["felt_spearman"].get<double>(), 0.0}, study.points);
        roughness[order[pos]] += j["felt_roughness"].get<double>();
        spearman[order[pos]] += j["felt_spearman"].get<double>();
        ++count;
      }
    score[order[pos]] = sum / count;
    roughness[order[pos]] /= count;
    spearman[order[pos]] /= count;
  }

  // The answers: items of the "visual" dimension alike in every condition (the same picture), the
  // others from what was felt; each with the participant's noise.
  std::string answers = "condition,item,answer\n";
  for (std::size_t c = 0; c < study.conditions.size(); ++c)
    for (std::size_t q = 0; q < study.questions.size(); ++q) {
      const double model = study.questions[q].dimension == "visual" ? 1.0 + 0.75 * (study.points - 1) : score[c];
      answers += fmt::format("{},{},{}\n", study.conditions[c].name, study.questions[q].id,
                             clampRound(model + draw(settings.simulated, settings.participant, c, q), 1, study.points));
    }
  std::string comparisons = "item,rating\n";
  for (std::size_t d = 0; d < study.comparisons.size(); ++d) {
    const StudyComparison& x = study.comparisons[d];
    const double model = score[x.b] - score[x.a];  // negative: the first felt better
    comparisons += fmt::format("{},{}\n", x.id,
                               clampRound(model + draw(settings.simulated, settings.participant,
                                                       study.conditions.size(), study.questions.size() + d),
                                          -study.comparisonRange, study.comparisonRange));
  }
  // Free text: what was felt in each condition, and which felt best.
  nlohmann::json freeText = nlohmann::json::array();
  const std::size_t best = std::size_t(std::max_element(score.begin(), score.end()) - score.begin());
  for (const StudyFreeText& f : study.freeTexts) {
    if (!f.perCondition) {
      freeText.push_back({{"item", f.id}, {"text", fmt::format("{} felt best.", study.conditions[best].name)}});
      continue;
    }
    for (std::size_t c : order)
      freeText.push_back({{"item", f.id},
                          {"condition", study.conditions[c].name},
                          {"text", fmt::format("The force {} as I pressed (roughness {:.2f}, loading Spearman {:.3f}).",
                                               roughness[c] <= 1.1 && spearman[c] >= 0.9 ? "grew smoothly" : "jumped",
                                               roughness[c], spearman[c])}});
  }
  nlohmann::json who{{"participant", fmt::format("P{}", settings.participant)},
                     {"number", settings.participant},
                     {"simulated", true},
                     {"seed", settings.simulated.seed},
                     {"order", nlohmann::json::array()}};
  for (std::size_t c : order) who["order"].push_back(study.conditions[c].name);
  writeFile(me / "answers.csv", answers);
  writeFile(me / "comparisons.csv", comparisons);
  writeFile(me / "free_text.json", freeText.dump(2) + "\n");
  writeFile(me / "participant.json", who.dump(2) + "\n");
  return result;
}

}  // namespace vrd
