#pragma once
// `vrdeform soak [SCENE] --steps N`: a long run of a scene whose scripted hand repeats its actions,
// watching resident memory, NaN events, volume drift and step time for growth (docs/loop.md).

#include <CLI/CLI.hpp>
#include <functional>

namespace vrd {

/// Adds the `soak` command to `app`. The returned function runs it and returns the exit code (0
/// every check passed, 1 one failed or the run did); vrd::Error (bad input) propagates, reported as 2.
std::function<int()> addSoakCommand(CLI::App& app);

}  // namespace vrd
