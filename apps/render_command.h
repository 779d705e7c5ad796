#pragma once
// `vrdeform render SCENE --out DIR`: run a scene with its scripted hand and write what it looks
// like, headless: PNG frames and, when ffmpeg is on PATH, an MP4 (docs/viewer.md).

#include <CLI/CLI.hpp>
#include <functional>

namespace vrd {

/// Adds the `render` command to `app`. The returned function runs it and returns the exit code
/// (0 fine, 1 the run or the rendering failed); vrd::Error (bad input) propagates, reported as 2.
std::function<int()> addRenderCommand(CLI::App& app);

}  // namespace vrd
