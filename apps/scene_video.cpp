#include "scene_video.h"

#include <fmt/format.h>

#include <chrono>
#include <cstdio>

#include "vrdeform/error.h"

namespace vrd {
namespace {

double msSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

void addVideoOptions(CLI::App& command, VideoOptions& options) {
  command.add_option("--fps", options.fps, "Frames per second of simulated time")
      ->check(CLI::Range(0.1, 1000.0))
      ->capture_default_str();
  command
      .add_option_function<std::string>(
          "--size",
          [&options](const std::string& s) {
            int w = 0, h = 0;
            char x = 0, extra = 0;
            if (std::sscanf(s.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') || w < 16 ||
                h < 16 || w > 8192 || h > 8192)
              throw CLI::ValidationError("--size", "expected WIDTHxHEIGHT within 16x16 .. 8192x8192, got '" + s + "'");
            options.width = w;
            options.height = h;
          },
          "Frame size in pixels, WIDTHxHEIGHT (default 640x480)")
      ->type_name("WxH");
  addColorMapOption(command, options.colorMap);
}

void addColorMapOption(CLI::App& command, ColorMap& colorMap) {
  command
      .add_option_function<std::string>(
          "--color-map",
          [&colorMap](const std::string& s) {
            const std::optional<ColorMap> map = parseColorMap(s);
            if (!map)
              throw CLI::ValidationError("--color-map", "expected none, strain, volume or force, got '" + s + "'");
            colorMap = *map;
          },
          "Colour the bodies by: none, strain (edge stretch), volume (volume change) or force (each particle's "
          "constraint force, N)")
      ->type_name("MAP");
}

SceneVideo::SceneVideo(const BuiltScene& scene, const std::filesystem::path& dir, const VideoOptions& options)
    : scene_(scene), options_(options), renderer_(scene, options.width, options.height), recorder_(dir, options.fps) {
  settings_.colorMap = options.colorMap;
  // Framed as the bodies lie now, settled.
  captureSnapshot(snapshot_, *scene.world, nullptr, 0, 0.0);
  captureConstraintForces(snapshot_, *scene.world);
  settings_.colorRange = defaultColorRange(options.colorMap, snapshot_);
  renderer_.render(snapshot_, camera_, settings_);
  camera_ = renderer_.framingCamera();
  fmt::print("rendering {}x{} frames at {:g} fps with {}\n", options.width, options.height, options.fps,
             renderer_.description());
}

void SceneVideo::afterStep(const RunStep& step) {
  // Frame n shows the first step that ends at or after n / fps (half a step early counts).
  const double dt = scene_.world->settings().timeStep;
  if (step.time + 0.5 * dt < double(recorder_.frames()) / options_.fps) return;
  const auto start = std::chrono::steady_clock::now();
  captureSnapshot(snapshot_, *scene_.world, step.session, step.step + 1, step.time);
  if (options_.colorMap == ColorMap::ConstraintForce) captureConstraintForces(snapshot_, *scene_.world);
  const Image image = renderer_.render(snapshot_, camera_, settings_);
  renderMs_ += msSince(start);
  const auto written = std::chrono::steady_clock::now();
  recorder_.add(image);
  writeMs_ += msSince(written);
}

std::vector<std::filesystem::path> SceneVideo::finish() {
  const std::size_t n = recorder_.frames();
  std::vector<std::filesystem::path> files;
  if (n == 0) return files;
  fmt::print("rendered {} frames: {:.2f} ms per frame to draw and read back, {:.2f} ms to write the PNG\n", n,
             renderMs_ / double(n), writeMs_ / double(n));
  files.push_back(std::filesystem::path("frames") / "frame_00000.png");
  if (n > 1) files.push_back(std::filesystem::path("frames") / fmt::format("frame_{:05}.png", n - 1));
  const std::filesystem::path video = recorder_.encodeVideo();
  if (video.empty())
    fmt::print("no ffmpeg on PATH: frames only (install ffmpeg for video.mp4)\n");
  else
    files.push_back(video.filename());
  return files;
}

}  // namespace vrd
