#pragma once
// `vrdeform touch MESH`: a scripted hand pokes or grasps a mesh resting on the ground; prints the
// haptic force over time, records the session and replays a recording bit for bit.

#include <CLI/CLI.hpp>
#include <functional>

namespace vrd {

/// Adds the `touch` command to `app` (after app's version flag, which a recording stores). The
/// returned function runs it and returns the process exit code (0 fine, 1 a replay differs from
/// its recording, 2 bad input; vrd::Error propagates for the caller to report as 2).
std::function<int()> addTouchCommand(CLI::App& app);

}  // namespace vrd
