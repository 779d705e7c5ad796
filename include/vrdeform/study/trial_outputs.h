#pragma once
// What a live study trial's loop outputs (docs/study.md), whichever front end runs it: the
// condition's device gets the force (condition B's the baseline instead), and the signal and the
// task events are recorded into the trial's folder.

#include <filesystem>
#include <optional>

#include "vrdeform/devices/csv_recorder.h"
#include "vrdeform/devices/haptic_output.h"
#include "vrdeform/devices/osc_output.h"
#include "vrdeform/scene/simulation_loop.h"
#include "vrdeform/study/study_spec.h"
#include "vrdeform/study/trial_events.h"

namespace vrd {

class TrialOutputs {
 public:
  /// Adds the outputs of a trial of `condition` to `loop`: its device (`glove`, the participant's
  /// glove, may be null; an OSC device is opened here), and the signal recorded into `forces`
  /// (CSV) with the task events. Throws vrd::Error when the OSC address or the file is unusable.
  TrialOutputs(SimulationLoopSettings& loop, const BuiltScene& scene, const StudyCondition& condition,
               HapticOutput* glove, const std::filesystem::path& forces);
  TrialOutputs(const TrialOutputs&) = delete;
  TrialOutputs& operator=(const TrialOutputs&) = delete;

  /// After the loop stopped: forces.csv complete, events.csv and latency.csv beside it. Throws
  /// vrd::Error when the signal could not be written.
  void finish(const SimulationLoop& loop);

 private:
  std::optional<OscOutput> osc_;
  std::optional<BaselineAsForce> baseline_;
  std::optional<CsvRecorder> recorder_;
  std::optional<TrialEvents> events_;
};

}  // namespace vrd
