#pragma once
// `vrdeform touch MESH`: the hand pokes (or, with a script, grasps) any mesh resting on the ground.
// A thin front end of the scenes: the scene of the mesh alone (sceneOfMesh, the scene files'
// defaults) changed by its options, run as `vrdeform run` runs a scene (scene_runner.h).

#include <CLI/CLI.hpp>
#include <functional>

namespace vrd {

/// Adds the `touch` command to `app`. The returned function runs it and returns the process exit code (0 fine, 1 a
/// replay differs from its recording, 2 bad input; vrd::Error propagates for the caller to report as 2).
std::function<int()> addTouchCommand(CLI::App& app);

}  // namespace vrd
