#pragma once
// What a study file says (docs/study.md): a within-subject haptics study as the paper ran it.
// Conditions (a scene, its solver and haptic settings, and the force the glove gets), tasks done
// in each, trials, rests, the questionnaire (7-point items in dimensions, direct comparisons of the
// conditions) and the counterbalancing of the conditions' order. Plain data, checked by the parser
// (study_file.h).

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "vrdeform/scene/scene_spec.h"

namespace vrd {

/// Which force drives the glove in a condition: the paper's condition A (the solver's multipliers
/// through Algorithm 2) or condition B (the vendor-style baseline, haptics/baseline.h).
enum class StudyForce { Multipliers, Baseline };

/// Where a condition's force goes: the participant's WEART glove (`study run --weart`), nowhere (a
/// visual-only condition: the glove, if any, still tracks the hand but gets no force), or OSC over UDP
/// to another device (the glove, if any, tracks the hand).
enum class StudyDevice { Glove, None, Osc };

struct StudyCondition {
  std::string name;   ///< unique; the data and the analysis name conditions by it
  std::string scene;  ///< a built-in scene's name or a scene file (absolute once loaded)
  StudyForce force = StudyForce::Multipliers;
  StudyDevice device = StudyDevice::Glove;
  std::string osc;  ///< HOST:PORT of the OSC device (StudyDevice::Osc)
  /// The scene as the condition runs it: loaded, with the condition's own [solver] and [haptics]
  /// keys over the scene's (the rest as the scene has it).
  SceneSpec spec;
};

/// When a task's trial ends before its length (study/task_end.h).
enum class TaskEnd {
  Time,          ///< after `seconds`
  Release,       ///< once the hand has touched a body and then left it untouched for half a second
  GraspRelease,  ///< once a grasp has held a body and then let it go
};

struct StudyTask {
  std::string name;          ///< unique, e.g. "poke"
  std::string instructions;  ///< shown to the participant before the task's first trial
  double seconds = 0.0;      ///< how long a trial lasts at most; 0: the scene's own length
  TaskEnd end = TaskEnd::Time;
};

/// A practice trial before the first condition, so that the participant learns the set-up; its data
/// is kept (P<k>/practice/) but not analysed.
struct StudyPractice {
  StudyCondition condition;  ///< the scene and force practised on (named "practice")
  StudyTask task;            ///< its instructions and length (named "practice")
};

/// A Likert item: a statement rated on 1..points between two anchors.
struct StudyQuestion {
  std::string id;         ///< unique, e.g. "H1"
  std::string dimension;  ///< e.g. "haptic"; items are summarised per dimension too
  std::string text;
  std::string low = "strongly disagree", high = "strongly agree";  ///< anchors of 1 and `points`
};

/// A direct comparison asked once all conditions are done, rated on -range..range: negative
/// favours condition `a`, 0 no difference, positive condition `b` (the paper's D1-D4).
struct StudyComparison {
  std::string id;  ///< unique among questions and comparisons, e.g. "D1"
  std::string text;
  std::size_t a = 0, b = 1;  ///< the conditions compared (indices)
};

/// A free-text item: a question answered in the participant's own words, after each condition or
/// once after all of them. Kept as written (free_text.json, the analysis's free_text.csv and
/// report), not scored.
struct StudyFreeText {
  std::string id;  ///< unique among questions, comparisons and free-text items, e.g. "F1"
  std::string text;
  bool perCondition = true;  ///< asked after each condition; false: once, after all conditions
};

enum class Counterbalancing {
  LatinSquare,  ///< participant k's order from Williams' balanced Latin square (metrics/latin_square.h)
  Fixed,        ///< every participant in the file's order
};

struct StudySpec {
  std::string name;
  std::string description;
  std::string source;  ///< the file it came from
  std::vector<StudyCondition> conditions;
  std::vector<StudyTask> tasks;
  std::optional<StudyPractice> practice;
  int trials = 3;           ///< per task and condition
  double restSeconds = 0;   ///< between conditions
  int points = 7;           ///< of every Likert item
  int comparisonRange = 3;  ///< direct comparisons are rated on -range..range
  std::vector<StudyQuestion> questions;
  std::vector<StudyComparison> comparisons;
  std::vector<StudyFreeText> freeTexts;
  Counterbalancing order = Counterbalancing::LatinSquare;

  /// Participant k's (from 1) order of the conditions, as indices into `conditions`.
  std::vector<std::size_t> orderOf(std::size_t participant) const;
  /// The dimensions of the questions, in the order they first appear.
  std::vector<std::string> dimensions() const;
};

}  // namespace vrd
