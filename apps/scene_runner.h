#pragma once
// The one way the command line runs a scene, shared by `vrdeform run SCENE` and `vrdeform touch
// MESH` (a scene of one mesh poked by the hand): build and settle it (Ctrl-C stops any phase),
// print what was built, run it with the scripted hand, a WEART glove or a recording's hand, show
// the timeline, print the summary, write the outputs, record or check a replay.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "scene_video.h"
#include "vrdeform/interact/session_recording.h"
#include "vrdeform/scene/scene_spec.h"

namespace vrd {

struct RunOptions {
  std::string out, weart, osc, forces, record, replay;
  double seconds = 0.0;      ///< 0: the scene's (a glove: until Ctrl-C)
  std::uint64_t steps = 0;   ///< instead of seconds; 0: none given
  double reportEvery = 0.5;  ///< s between timeline rows (when not on a terminal)
  bool render = false;       ///< --render: frames (and a video) into out
  VideoOptions video;
};

/// Adds the options every scene-running command takes: --seconds, --steps, --out, --report-every,
/// --weart, --forces, --osc, --record, --replay, --render and the video options.
void addRunOptions(CLI::App& command, RunOptions& options);

/// Loads `options.replay` when given (refusing --record and --weart beside it) and checks that it
/// is a recording of `tool`. Throws vrd::Error.
std::optional<SessionRecording> loadReplay(const RunOptions& options, std::string_view tool);

/// Builds, runs and reports `spec`. `recorded`: what --record keeps for the command to rebuild the
/// scene (its "tool" first); each body's mesh fingerprint is added, and checked by a replay.
/// Returns the exit status: 0, or 1 when the run failed part-way or a replay differs; throws
/// vrd::Error for bad input and vrd::Stopped when Ctrl-C stops the build.
int runSceneCommand(const SceneSpec& spec, const RunOptions& options,
                    std::vector<std::pair<std::string, std::string>> recorded,
                    std::optional<SessionRecording> replaying);

}  // namespace vrd
