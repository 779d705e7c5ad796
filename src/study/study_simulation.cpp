#include "vrdeform/study/study_simulation.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <vector>

#include "vrdeform/core/write_file.h"
#include "vrdeform/error.h"
#include "vrdeform/metrics/signal_quality.h"
#include "vrdeform/scene/scene_run.h"
#include "vrdeform/study/participant_progress.h"
#include "vrdeform/study/task_end.h"
#include "vrdeform/study/trial_events.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;

// What a trial's index finger felt during the scene's first scripted poke: the glove's signal
// (the force for condition A, the baseline for B) against the indentation.
FeltSignal feltInTrial(const SceneSpec& spec, const std::vector<double>& depth, const std::vector<double>& felt) {
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
    FeltSignal f;
    f.peak = q.peak;
    if (std::isfinite(q.roughness)) f.roughness = q.roughness;
    f.spearman = std::isfinite(q.loadingSpearman) ? q.loadingSpearman : 0.0;  // no rise with depth: nothing graded
    return f;
  }
  return {};
}

// The model answer (1..points) for what was felt: a clean, graded signal (roughness 1, loading
// Spearman 1) rates near the top, a stepped or ungraded one near the middle.
double feltScore(const FeltSignal& f, int points) {
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

// The scene run with its scripted hand for the task's length into the progress's scratch folder.
TrialRecord runTrial(ParticipantProgress& progress, const StudyRunSettings& settings) {
  const StudyStep step = progress.next();
  const StudyCondition& c = progress.condition(step);
  SceneSpec spec = c.spec;
  spec.output.meshEvery = 0.0;
  spec.output.plots = false;
  SceneBuildObserver observer;
  observer.stop = settings.stop;
  BuiltScene scene = buildScene(spec, observer);
  RunSettings run;
  run.steps = progress.trialSteps(step);
  run.outDir = progress.beginTrial();
  std::vector<double> depth, felt;
  bool stopped = false, ended = false;
  TaskEndWatch end(progress.task(step).end);
  TrialEvents events;
  run.outputs.push_back(&events);
  run.afterStep = [&](const RunStep& s) {
    if (s.session) {  // a scene without a hand: nothing felt
      const FingerHaptics& f = s.session->haptics().fingers[int(Finger::Index)];
      depth.push_back(f.depth);
      felt.push_back(c.force == StudyForce::Baseline ? f.baseline : f.force);
      ended = end.update(s.session->inContact(), s.session->grasp().active(), s.time);
    }
    stopped = settings.stop && settings.stop();
    return !stopped && !ended;
  };
  const auto began = std::chrono::steady_clock::now();
  const RunSummary summary = runScene(scene, run);
  if (stopped) {
    std::error_code error;
    fs::remove_all(run.outDir, error);
    throw Stopped(
        fmt::format("stopped during trial {} of {} in condition {}", step.trial, progress.task(step).name, c.name));
  }
  writeFile(run.outDir / "events.csv", events.csv());
  const TrialRecord record{summary.steps,
                           std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count(),
                           feltInTrial(spec, depth, felt), ended};
  progress.finishTrial(record);
  return record;
}

// The answers after a condition from what was felt in its trials: items of the "visual"
// dimension alike in every condition (the same picture), the others from the felt score; each
// with the participant's noise. Free text: whether the force grew smoothly or jumped.
ConditionAnswers answerCondition(const ParticipantProgress& progress, const SimulatedParticipant& simulated,
                                 double score, const FeltSignal& mean) {
  const StudySpec& study = progress.study();
  const std::size_t c = progress.next().condition;
  ConditionAnswers a;
  for (std::size_t q = 0; q < study.questions.size(); ++q) {
    const double model = study.questions[q].dimension == "visual" ? 1.0 + 0.75 * (study.points - 1) : score;
    a.likert.push_back(clampRound(model + draw(simulated, progress.participant(), c, q), 1, study.points));
  }
  for (const StudyFreeText& f : study.freeTexts)
    if (f.perCondition)
      a.freeText.push_back(fmt::format("The force {} as I pressed (roughness {:.2f}, loading Spearman {:.3f}).",
                                       mean.roughness <= 1.1 && mean.spearman >= 0.9 ? "grew smoothly" : "jumped",
                                       mean.roughness, mean.spearman));
  return a;
}

// Each direct comparison: the difference of the two conditions' felt scores; free text: which felt best.
FinalAnswers answerStudy(const ParticipantProgress& progress, const SimulatedParticipant& simulated,
                         const std::vector<double>& score) {
  const StudySpec& study = progress.study();
  FinalAnswers a;
  for (std::size_t d = 0; d < study.comparisons.size(); ++d) {
    const StudyComparison& x = study.comparisons[d];
    const double model = score[x.b] - score[x.a];  // negative: the first felt better
    a.comparisons.push_back(
        clampRound(model + draw(simulated, progress.participant(), study.conditions.size(), study.questions.size() + d),
                   -study.comparisonRange, study.comparisonRange));
  }
  const std::size_t best = std::size_t(std::max_element(score.begin(), score.end()) - score.begin());
  for (const StudyFreeText& f : study.freeTexts)
    if (!f.perCondition) a.freeText.push_back(fmt::format("{} felt best.", study.conditions[best].name));
  return a;
}

}  // namespace

StudyRunResult runSimulatedParticipant(const StudySpec& study, const StudyRunSettings& settings) {
  ParticipantProgress progress(study, settings.dataDir, settings.participant, true, settings.simulated.seed);
  StudyRunResult result;
  result.trialsKept = progress.trialsKept();
  // A condition's mean felt signal and score over its trials (finished now or by an earlier run).
  const auto felt = [&](std::size_t position) {
    FeltSignal mean{0.0, 0.0, 0.0};
    double score = 0.0;
    int count = 0;
    for (std::size_t t = 0; t < study.tasks.size(); ++t)
      for (int r = 1; r <= study.trials; ++r) {
        const TrialRecord rec =
            progress.trialRecord({StudyStepKind::Trial, position, progress.order()[position], t, r});
        if (!rec.felt)
          throw Error(fmt::format("P{}: a trial of a live participant; not simulated", settings.participant));
        mean.roughness += rec.felt->roughness;
        mean.spearman += rec.felt->spearman;
        score += feltScore(*rec.felt, study.points);
        ++count;
      }
    mean.roughness /= count;
    mean.spearman /= count;
    return std::pair(mean, score / count);
  };
  for (StudyStep step = progress.next(); step.kind != StudyStepKind::Done; step = progress.next()) {
    if (settings.stop && settings.stop()) throw Stopped("stopped between trials");
    switch (step.kind) {
      case StudyStepKind::Practice:
        runTrial(progress, settings);
        ++result.trialsRun;
        if (settings.log) settings.log(fmt::format("P{}: practice", settings.participant));
        break;
      case StudyStepKind::Trial: {
        const TrialRecord r = runTrial(progress, settings);
        ++result.trialsRun;
        if (settings.log)
          settings.log(fmt::format("P{}: condition {} ({} of {}), {} trial {}: felt roughness {:.2f}, Spearman {:.3f}",
                                   settings.participant, study.conditions[step.condition].name, step.position + 1,
                                   study.conditions.size(), study.tasks[step.task].name, step.trial, r.felt->roughness,
                                   r.felt->spearman));
        break;
      }
      case StudyStepKind::ConditionQuestions: {
        const auto [mean, score] = felt(step.position);
        progress.answer(answerCondition(progress, settings.simulated, score, mean));
        break;
      }
      case StudyStepKind::Rest:  // a simulated participant needs none
        progress.finishRest();
        break;
      case StudyStepKind::StudyQuestions: {
        std::vector<double> score(study.conditions.size(), 0.0);
        for (std::size_t pos = 0; pos < progress.order().size(); ++pos) score[progress.order()[pos]] = felt(pos).second;
        progress.answer(answerStudy(progress, settings.simulated, score));
        break;
      }
      case StudyStepKind::Done:
        break;
    }
  }
  return result;
}

}  // namespace vrd
