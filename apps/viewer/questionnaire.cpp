#include "questionnaire.h"

#include <fmt/format.h>
#include <imgui.h>

#include <algorithm>

namespace vrd {

Questionnaire::Questionnaire(const StudySpec& study, const std::vector<std::size_t>& order, bool final)
    : items_(questionnaireItems(study, order, final)) {
  for (const QuestionnaireItem& item : items_)
    if (item.rated)
      rated_.push_back(kUnanswered);
    else
      buffers_.emplace_back(4096, '\0');
}

bool Questionnaire::complete() const {
  return std::none_of(rated_.begin(), rated_.end(), [](int v) { return v == kUnanswered; });
}

bool Questionnaire::draw() {
  std::size_t r = 0, t = 0;
  for (const QuestionnaireItem& item : items_) {
    ImGui::TextWrapped("%s", item.text.c_str());
    if (!item.rated) {
      std::vector<char>& b = buffers_[t];
      ImGui::InputTextMultiline(fmt::format("##text{}", t++).c_str(), b.data(), b.size(),
                                ImVec2(-1.0f, 4.0f * ImGui::GetTextLineHeight()));
      continue;
    }
    ImGui::PushID(int(r));
    ImGui::TextDisabled("%s", item.lowAnchor.c_str());
    for (int v = item.low; v <= item.high; ++v) {
      ImGui::SameLine();
      ImGui::RadioButton(fmt::format("{}##{}", v, v).c_str(), &rated_[r], v);
    }
    ImGui::SameLine();
    ImGui::TextDisabled("%s", item.highAnchor.c_str());
    ImGui::PopID();
    ImGui::Spacing();
    ++r;
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
  std::vector<std::string> texts;
  dryRunAnswers(items_, rated_, texts);
  for (std::size_t t = 0; t < texts.size(); ++t)
    fmt::format_to_n(buffers_[t].data(), buffers_[t].size() - 1, "{}", texts[t]);
}

std::vector<std::string> Questionnaire::texts() const {
  std::vector<std::string> out;
  for (const std::vector<char>& b : buffers_) out.emplace_back(b.data());
  return out;
}

ConditionAnswers Questionnaire::conditionAnswers() const { return {rated_, texts()}; }

FinalAnswers Questionnaire::finalAnswers() const { return {rated_, texts()}; }

}  // namespace vrd
