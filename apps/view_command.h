#pragma once
// `vrdeform view [SCENE]`: the desktop viewer; poke and pinch with the mouse or a WEART glove
// (docs/viewer.md).

#include <CLI/CLI.hpp>
#include <functional>

namespace vrd {

/// Adds the `view` command to `app`. The returned function runs it and returns the exit code (0
/// fine, 1 no window could be opened or the simulation failed); vrd::Error propagates (2).
std::function<int()> addViewCommand(CLI::App& app);

}  // namespace vrd
