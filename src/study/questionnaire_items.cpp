#include "vrdeform/study/questionnaire_items.h"

#include <fmt/format.h>

#include <algorithm>

namespace vrd {

std::vector<QuestionnaireItem> questionnaireItems(const StudySpec& study, const std::vector<std::size_t>& order,
                                                  bool final) {
  std::vector<QuestionnaireItem> items;
  if (!final) {
    for (const StudyQuestion& q : study.questions) items.push_back({true, q.text, 1, study.points, q.low, q.high});
  } else {
    const auto part = [&](std::size_t c) {
      return fmt::format("part {}", std::size_t(std::find(order.begin(), order.end(), c) - order.begin()) + 1);
    };
    for (const StudyComparison& x : study.comparisons)
      items.push_back({true, x.text, -study.comparisonRange, study.comparisonRange, part(x.a), part(x.b)});
  }
  for (const StudyFreeText& f : study.freeTexts)
    if (f.perCondition != final) items.push_back({false, f.text, 0, 0, {}, {}});
  return items;
}

void dryRunAnswers(const std::vector<QuestionnaireItem>& items, std::vector<int>& ratings,
                   std::vector<std::string>& texts) {
  ratings.clear();
  texts.clear();
  for (const QuestionnaireItem& item : items)
    if (item.rated)
      ratings.push_back((item.low + item.high) / 2);
    else
      texts.emplace_back("(dry run)");
}

}  // namespace vrd
