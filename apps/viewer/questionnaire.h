#pragma once
// A study's questionnaire in the desktop viewer (`vrdeform study run`, docs/study.md): the items
// (study/questionnaire_items.h) drawn with Dear ImGui; Submit is offered once every rated item has
// an answer.

#include <string>
#include <vector>

#include "vrdeform/study/questionnaire_items.h"

namespace vrd {

class Questionnaire {
 public:
  /// After a condition (`final` false) or after all of them; `order` is the participant's order of
  /// the conditions.
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
  std::vector<std::string> texts() const;

  std::vector<QuestionnaireItem> items_;
  std::vector<int> rated_;                  // per rated item
  std::vector<std::vector<char>> buffers_;  // per free-text item, its edit buffer
};

}  // namespace vrd
