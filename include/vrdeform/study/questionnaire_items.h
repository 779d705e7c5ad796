#pragma once
// What a questionnaire asks, for any front end that shows it (the desktop viewer's panel, the VR
// page): after a condition its Likert items and the free-text items asked after each condition;
// after all conditions the direct comparisons and the free-text items asked once.

#include <cstddef>
#include <string>
#include <vector>

#include "vrdeform/study/participant_progress.h"

namespace vrd {

struct QuestionnaireItem {
  bool rated = true;  ///< rated on low..high between two anchors; false: answered in words
  std::string text;
  int low = 0, high = 0;              ///< rated: the scale
  std::string lowAnchor, highAnchor;  ///< rated: the words at low and at high
};

/// The items asked after a condition (`final` false) or after all of them, rated items first, in
/// the study's order. A comparison names the conditions as the participant met them ("part 1",
/// "part 2"; `order` is theirs), not by name.
std::vector<QuestionnaireItem> questionnaireItems(const StudySpec& study, const std::vector<std::size_t>& order,
                                                  bool final);

/// The answers a dry run gives: every rated item its scale's middle, every text "(dry run)".
void dryRunAnswers(const std::vector<QuestionnaireItem>& items, std::vector<int>& ratings,
                   std::vector<std::string>& texts);

}  // namespace vrd
