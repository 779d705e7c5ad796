#pragma once
// How a command builds its scene: the builder's lines printed, settling's progress shown on a
// terminal, and Ctrl-C (a StopSignals the command installed first) stopping meshing, settling or
// calibration with vrd::Stopped, which main reports (exit status 130).

#include "vrdeform/devices/stop_signals.h"
#include "vrdeform/scene/scene_builder.h"

namespace vrd {

/// `print`: the builder's lines and the settling bar; false: silent (Ctrl-C still stops it).
SceneBuildObserver commandObserver(const StopSignals& signals, bool print = true);

/// The line a command starts a scene with: "scene NAME: DESCRIPTION", or "scene NAME" without one.
void printSceneTitle(const SceneSpec& spec);

}  // namespace vrd
