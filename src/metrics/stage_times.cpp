#include "vrdeform/metrics/stage_times.h"

namespace vrd {

std::string_view stageName(Stage stage) {
  static constexpr std::string_view kNames[kStageCount] = {
      "predict",    "detect",  "distance",  "volume",       "strain",   "strain_volume", "bend", "shape_matching",
      "attachment", "contact", "fingertip", "body_contact", "finalise", "interact",      "force"};
  return stage < Stage::Count ? kNames[std::size_t(stage)] : "?";
}

double StageTimes::solveMs() const {
  double sum = 0.0;
  for (std::size_t s = std::size_t(Stage::Distance); s <= std::size_t(Stage::BodyContact); ++s) sum += ms[s];
  return sum;
}

double StageTimes::totalMs() const {
  double sum = 0.0;
  for (double t : ms) sum += t;
  return sum;
}

}  // namespace vrd
