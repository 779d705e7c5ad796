#pragma once
// `vrdeform run SCENE`: simulate a scene headless with its scripted hand (or a WEART glove), print
// a summary and write the outputs (docs/scenes.md).

#include <CLI/CLI.hpp>
#include <functional>

namespace vrd {

/// Adds the `run` and `scenes` commands to `app`. The returned function runs whichever was given
/// and returns the exit code (0 fine, 1 the run failed part-way); vrd::Error (bad input)
/// propagates for the caller to report as 2.
std::function<int()> addRunCommands(CLI::App& app);

}  // namespace vrd
