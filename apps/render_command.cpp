#include "render_command.h"

#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <optional>
#include <string>

#include "build_observer.h"
#include "scene_video.h"
#include "vrdeform/core/write_file.h"
#include "vrdeform/devices/stop_signals.h"
#include "vrdeform/error.h"
#include "vrdeform/scene/scene_library.h"

namespace vrd {
namespace {

struct RenderArgs {
  std::string scene, out;
  double seconds = 0.0;  // 0: the scene's
  VideoOptions video;
};

int render(const RenderArgs& a) {
  prepareOutputFolder(a.out);
  const SceneSpec spec = loadSceneByName(a.scene);
  printSceneTitle(spec);
  const StopSignals signals;
  BuiltScene scene = buildScene(spec, commandObserver(signals));
  std::optional<SceneVideo> video;
  try {
    video.emplace(scene, a.out, a.video);
  } catch (const Error& e) {
    fmt::print(stderr, "vrdeform: cannot render: {}\n", e.what());
    return 1;
  }
  const double seconds = a.seconds > 0.0 ? a.seconds : spec.seconds;
  RunSettings settings;
  settings.steps = std::max<std::uint64_t>(1, std::uint64_t(std::llround(seconds / spec.solver.timeStep)));
  settings.afterStep = [&](const RunStep& s) {
    video->afterStep(s);
    return !signals.requested();
  };
  try {
    const RunSummary summary = runScene(scene, settings);
    fmt::print("simulated {} steps ({:.3f} s) in {:.3f} s wall time, rendering included\n", summary.steps,
               double(summary.steps) * spec.solver.timeStep, summary.wallSeconds);
  } catch (const Error& e) {
    fmt::print(stderr, "vrdeform: the run failed: {}\n", e.what());
    video->finish();
    return 1;
  }
  const auto files = video->finish();
  fmt::print("wrote into {}:", a.out);
  for (const auto& f : files) fmt::print(" {}", f.generic_string());
  fmt::print("\n");
  return 0;
}

}  // namespace

std::function<int()> addRenderCommand(CLI::App& app) {
  auto a = std::make_shared<RenderArgs>();
  CLI::App* cmd = app.add_subcommand(
      "render", "Run a scene headless and write its frames as PNG (and an MP4 when ffmpeg is on PATH)");
  cmd->add_option("scene", a->scene, "A built-in scene (`vrdeform scenes`) or a scene file (.toml)")->required();
  cmd->add_option("--out", a->out, "Write DIR/frames/frame_NNNNN.png and DIR/video.mp4 here")->required();
  cmd->add_option("--seconds", a->seconds, "Simulated time after settling (default: the scene's)")
      ->check(CLI::Range(1e-6, 1e6));
  addVideoOptions(*cmd, a->video);
  return [a, cmd]() -> int { return *cmd ? render(*a) : 0; };
}

}  // namespace vrd
