#pragma once
// A study's questionnaire in the desktop viewer (`vrdeform study run`, docs/study.md): the Likert
// items and free-text items after a condition, or the direct comparisons and free-text items after
// all of them, drawn with Dear ImGui; Submit is offered once every rated item has an answer.

#include <string>
#include <vector>

#include "vrdeform/study/participant_progress.h"

namespace vrd {

class Questionnaire {
 public:
  /// After a condition (`final` false) or after all of them; `order` is the participant's order of
  /// the conditions, so that a comparison names them as met ("part 1", "part 2"), not by name.
  Questionnaire(const StudySpec& study, const std::vector<std::size_t>& order, bool final);

  /// Draws the items in the current ImGui window; true when Submit is pressed.
  bool draw();
  /// Answers every rated item with its scale's middle and every text with "(dry run)".
  void answerForDryRun();
  ConditionAnswers conditionAnswers() const;
  FinalAnswers finalAnswers() const;

 private:
  static constexpr int kUnanswered = -1000;
  bool complete() const;

  const StudySpec& study_;
  std::vector<std::size_t> order_;
  bool final_;
  std::vector<int> rated_;                  // per Likert item or comparison
  std::vector<std::string> texts_;          // the free-text items asked now, their text
  std::vector<std::vector<char>> buffers_;  // their edit buffers
};

}  // namespace vrd
