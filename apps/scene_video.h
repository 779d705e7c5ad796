#pragma once
// Headless frames of a scene run (`vrdeform render`, `vrdeform run --render`): after each step whose
// time reaches the next frame's, the world is captured as a snapshot, drawn off screen from a
// fixed camera that frames the bodies, and written as DIR/frames/frame_NNNNN.png; at the end,
// DIR/video.mp4 when ffmpeg is on PATH.

#include <CLI/CLI.hpp>
#include <filesystem>
#include <optional>
#include <vector>

#include "vrdeform/render/frame_recorder.h"
#include "vrdeform/render/headless_renderer.h"
#include "vrdeform/scene/scene_run.h"

namespace vrd {

struct VideoOptions {
  double fps = 30.0;
  int width = 640, height = 480;
  ColorMap colorMap = ColorMap::None;
};

/// Adds --fps, --size WxH and --color-map to a command.
void addVideoOptions(CLI::App& command, VideoOptions& options);
/// Adds --color-map alone.
void addColorMapOption(CLI::App& command, ColorMap& colorMap);

class SceneVideo {
 public:
  /// Throws vrd::Error when no headless OpenGL context can be made or DIR cannot be written.
  SceneVideo(const BuiltScene& scene, const std::filesystem::path& dir, const VideoOptions& options);

  /// Renders a frame when one is due at the end of this step.
  void afterStep(const RunStep& step);
  /// Makes the video when it can; prints what was written and returns those paths, relative to DIR.
  std::vector<std::filesystem::path> finish();

 private:
  const BuiltScene& scene_;
  VideoOptions options_;
  HeadlessRenderer renderer_;
  FrameRecorder recorder_;
  OrbitCamera camera_;
  RenderSettings settings_;
  Snapshot snapshot_;
  double renderMs_ = 0.0, writeMs_ = 0.0;
};

}  // namespace vrd
