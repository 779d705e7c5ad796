#include "vrdeform/study/trial_outputs.h"

#include <fmt/format.h>

#include "vrdeform/core/write_file.h"
#include "vrdeform/devices/host_port.h"
#include "vrdeform/error.h"
#include "vrdeform/metrics/latency_stats.h"

namespace vrd {

TrialOutputs::TrialOutputs(SimulationLoopSettings& loop, const BuiltScene& scene, const StudyCondition& condition,
                           HapticOutput* glove, const std::filesystem::path& forces) {
  HapticOutput* device = condition.device == StudyDevice::Glove ? glove : nullptr;
  if (condition.device == StudyDevice::Osc) {
    const HostPort to = parseHostPort(condition.osc);
    device = &osc_.emplace(to.host, to.port);
  }
  if (device) loop.outputs.push_back(condition.force == StudyForce::Baseline ? &baseline_.emplace(*device) : device);
  loop.outputs.push_back(&recorder_.emplace(forces, scene.session.hand.fingers));
  loop.outputs.push_back(&events_.emplace());
}

void TrialOutputs::finish(const SimulationLoop& loop) {
  recorder_->flush();
  if (recorder_->failed())
    throw Error(
        fmt::format("{}: the trial's signal was not recorded: {}", recorder_->path().string(), recorder_->error()));
  const std::filesystem::path dir = recorder_->path().parent_path();
  writeFile(dir / "events.csv", events_->csv());
  writeFile(dir / "latency.csv", latencyCsv(loop.latency()));
}

}  // namespace vrd
