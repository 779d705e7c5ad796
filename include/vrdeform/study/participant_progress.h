#pragma once
// One participant's way through a study (docs/study.md): the step that comes next, from what their
// folder holds, and the files each finished step leaves. Every front end walks it the same way: a
// simulated participant headless, a live one in the desktop viewer (`vrdeform study run`). A
// finished trial or questionnaire is on disk whole (written aside and renamed into place), so a run
// stopped or killed at any point goes on from the first step not finished.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "vrdeform/study/study_spec.h"

namespace vrd {

enum class StudyStepKind {
  Practice,            ///< the practice trial (P<k>/practice/)
  Trial,               ///< a task's trial in a condition (P<k>/trials/<position>-<task>-<trial>/)
  ConditionQuestions,  ///< the Likert items and the free-text items asked after each condition
  Rest,                ///< before the next condition; not recorded: after a resume it is due again
  StudyQuestions,      ///< the direct comparisons and the free-text items asked once
  Done,
};

struct StudyStep {
  StudyStepKind kind = StudyStepKind::Done;
  std::size_t position = 0;   ///< in the participant's order (0: the condition met first)
  std::size_t condition = 0;  ///< index into study.conditions
  std::size_t task = 0;       ///< index into study.tasks
  int trial = 0;              ///< 1..study.trials
};

/// What a simulated participant's index finger felt in a trial's scripted poke (the glove's signal
/// against the indentation, metrics/signal_quality.h).
struct FeltSignal {
  double roughness = 1.0, spearman = 1.0, peak = 0.0;
};

/// A finished trial, as trial.json keeps it beside what the progress adds (condition, task, trial,
/// scene, substeps, iterations, when it finished).
struct TrialRecord {
  std::uint64_t steps = 0;         ///< simulation steps run
  double wallSeconds = 0.0;        ///< how long the trial took on the wall clock
  std::optional<FeltSignal> felt;  ///< simulated participants only
  bool endConditionMet = false;    ///< the task's end condition ended it, not its length
};

/// The answers to the questions asked after one condition.
struct ConditionAnswers {
  std::vector<int> likert;            ///< per study.questions, 1..points
  std::vector<std::string> freeText;  ///< per free-text item asked after each condition, in the study's order
};

/// The answers asked once, after all conditions.
struct FinalAnswers {
  std::vector<int> comparisons;       ///< per study.comparisons, -range..range
  std::vector<std::string> freeText;  ///< per free-text item asked once, in the study's order
};

class ParticipantProgress {
 public:
  /// Reads participant k's folder P<k> under `dataDir` (made when new) and writes participant.json
  /// (their number and order of the conditions; `simulated`, and the seed of simulated answers).
  /// Throws vrd::Error when the folder cannot be written or holds a record that is not one.
  ParticipantProgress(const StudySpec& study, const std::filesystem::path& dataDir, std::size_t participant,
                      bool simulated, std::uint64_t seed = 0);

  /// The first step not finished (a rest once the condition before it is answered, until finishRest()).
  StudyStep next() const { return next_; }
  const StudySpec& study() const { return study_; }
  std::size_t participant() const { return participant_; }
  const std::vector<std::size_t>& order() const { return order_; }
  const std::filesystem::path& folder() const { return folder_; }
  /// The condition a practice or trial step runs (the practice's own for Practice).
  const StudyCondition& condition(const StudyStep& step) const;
  const StudyTask& task(const StudyStep& step) const;
  /// The steps a practice or trial step runs at most: its task's seconds, else its scene's length.
  std::uint64_t trialSteps(const StudyStep& step) const;
  /// The folder a practice or trial step's files end up in.
  std::filesystem::path trialFolder(const StudyStep& step) const;
  /// Trials finished by an earlier run when this one began.
  std::size_t trialsKept() const { return kept_; }

  /// The scratch folder next()'s trial writes its files into while it runs, emptied.
  std::filesystem::path beginTrial();
  /// Writes trial.json into the scratch folder and renames it into place; next() moves on.
  void finishTrial(const TrialRecord& record);
  /// The record of a finished trial of the current participant (a simulated one's felt signal).
  TrialRecord trialRecord(const StudyStep& step) const;
  void finishRest();
  /// The answers after next()'s condition: kept in questionnaires/<position>.json and gathered into
  /// answers.csv and free_text.json. Throws vrd::Error for an answer off its scale or a count that
  /// does not match the study's items.
  void answer(const ConditionAnswers& answers);
  /// The answers after all conditions: questionnaires/final.json, comparisons.csv, free_text.json.
  void answer(const FinalAnswers& answers);

 private:
  void advance();
  void gatherAnswers() const;

  const StudySpec& study_;
  std::size_t participant_;
  std::vector<std::size_t> order_;
  std::filesystem::path folder_;
  StudyStep next_;
  std::size_t kept_ = 0;
  std::size_t restedBefore_ = 0;  // positions whose rest before them is done (this run)
};

}  // namespace vrd
