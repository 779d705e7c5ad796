#include "questionnaire.h"

#include <fmt/format.h>
#include <imgui.h>

#include <algorithm>

namespace vrd {

Questionnaire::Questionnaire(const StudySpec& study, const std::vector<std::size_t>& order, bool final)
    : study_(study), order_(order), final_(final) {
  rated_.assign(final ? study.comparisons.size() : study.questions.size(), kUnanswered);
  for (const StudyFreeText& f : study.freeTexts)
    if (f.perCondition != final) {
      texts_.push_back(f.text);
      buffers_.emplace_back(4096, '\0');
    }
}

bool Questionnaire::complete() const {
  return std::none_of(rated_.begin(), rated_.end(), [](int v) { return v == kUnanswered; });
}

bool Questionnaire::draw() {
  const auto scale = [&](std::size_t i, int lo, int hi, const std::string& left, const std::string& right) {
    ImGui::PushID(int(i));
    ImGui::TextDisabled("%s", left.c_str());
    for (int v = lo; v <= hi; ++v) {
      ImGui::SameLine();
      ImGui::RadioButton(fmt::format("{}##{}", v, v).c_str(), &rated_[i], v);
    }
    ImGui::SameLine();
    ImGui::TextDisabled("%s", right.c_str());
    ImGui::PopID();
    ImGui::Spacing();
  };
  if (!final_) {
    for (std::size_t q = 0; q < study_.questions.size(); ++q) {
      ImGui::TextWrapped("%s", study_.questions[q].text.c_str());
      scale(q, 1, study_.points, study_.questions[q].low, study_.questions[q].high);
    }
  } else {
    // A participant knows the conditions by when they met them.
    const auto part = [&](std::size_t c) {
      return fmt::format("part {}", std::size_t(std::find(order_.begin(), order_.end(), c) - order_.begin()) + 1);
    };
    for (std::size_t d = 0; d < study_.comparisons.size(); ++d) {
      const StudyComparison& x = study_.comparisons[d];
      ImGui::TextWrapped("%s", x.text.c_str());
      scale(d, -study_.comparisonRange, study_.comparisonRange, part(x.a), part(x.b));
    }
  }
  for (std::size_t t = 0; t < texts_.size(); ++t) {
    ImGui::TextWrapped("%s", texts_[t].c_str());
    ImGui::InputTextMultiline(fmt::format("##text{}", t).c_str(), buffers_[t].data(), buffers_[t].size(),
                              ImVec2(-1.0f, 4.0f * ImGui::GetTextLineHeight()));
  }
  ImGui::BeginDisabled(!complete());
  const bool submitted = ImGui::Button("Submit");
  ImGui::EndDisabled();
  if (!complete()) {
    ImGui::SameLine();
    ImGui::TextDisabled("(an answer to every rated item first)");
  }
  return submitted;
}

void Questionnaire::answerForDryRun() {
  const int middle = final_ ? 0 : (study_.points + 1) / 2;
  std::fill(rated_.begin(), rated_.end(), middle);
  for (std::vector<char>& b : buffers_) fmt::format_to_n(b.data(), b.size() - 1, "(dry run)");
}

ConditionAnswers Questionnaire::conditionAnswers() const {
  ConditionAnswers a{rated_, {}};
  for (const std::vector<char>& b : buffers_) a.freeText.emplace_back(b.data());
  return a;
}

FinalAnswers Questionnaire::finalAnswers() const {
  FinalAnswers a{rated_, {}};
  for (const std::vector<char>& b : buffers_) a.freeText.emplace_back(b.data());
  return a;
}

}  // namespace vrd
