#pragma once
// `vrdeform serve SCENE`: runs a scene's simulation loop in real time and serves the VR page, so
// that a headset (or any browser) shows the deforming bodies and drives the hand (docs/vr.md).

#include <CLI/CLI.hpp>
#include <functional>

namespace vrd {

/// Adds the `serve` command to `app`. The returned function runs it and returns the exit code (0
/// fine, 1 the simulation failed); vrd::Error (bad input) propagates for the caller to report as 2.
std::function<int()> addServeCommand(CLI::App& app);

}  // namespace vrd
