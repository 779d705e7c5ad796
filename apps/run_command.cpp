#include "run_command.h"

#include <fmt/format.h>

#include <memory>
#include <optional>
#include <string>

#include "scene_runner.h"
#include "vrdeform/error.h"
#include "vrdeform/scene/scene_library.h"

namespace vrd {
namespace {

struct RunArgs {
  std::string scene;
  int substeps = 0, iterations = 0;  // 0: the scene's
  RunOptions run;
};

// What a recording of `vrdeform run` keeps to run again: the scene as named and the solver's overrides.
constexpr std::string_view kRecordedSolver[] = {"substeps", "iterations"};

int run(RunArgs a) {
  std::optional<SessionRecording> replaying = loadReplay(a.run, "run");
  if (replaying) {
    const std::string* scene = replaying->setting("scene");
    if (!scene) throw Error(fmt::format("{}: no scene setting", a.run.replay));
    if (a.scene.empty()) a.scene = *scene;  // a scene named here replaces the recorded one (moved)
    for (std::string_view key : kRecordedSolver)
      if (const std::string* v = replaying->setting(key); v && *v != "0")
        (key == "substeps" ? a.substeps : a.iterations) = std::stoi(*v);
  }
  if (a.scene.empty()) throw Error("run: a SCENE is needed (or --replay FILE)");
  SceneSpec spec = loadSceneByName(a.scene);
  if (a.substeps > 0) spec.solver.substeps = a.substeps;
  if (a.iterations > 0) spec.solver.iterations = a.iterations;
  validateSolverSettings(spec.solver);
  return runSceneCommand(spec, a.run,
                         {{"tool", "run"},
                          {"scene", a.scene},
                          {"substeps", std::to_string(a.substeps)},
                          {"iterations", std::to_string(a.iterations)}},
                         std::move(replaying));
}

int listScenes() {
  for (const SceneEntry& e : builtinScenes()) {
    const SceneSpec s = loadSceneByName(e.file.string());
    fmt::print("{:<10} {}\n", e.name, s.description);
  }
  fmt::print("\n(scene files in {}; `vrdeform run NAME` runs one, `vrdeform run FILE.toml` your own)\n",
             sceneFolder().string());
  return 0;
}

}  // namespace

std::function<int()> addRunCommands(CLI::App& app) {
  auto a = std::make_shared<RunArgs>();
  CLI::App* run = app.add_subcommand("run", "Simulate a scene headless; print a summary; write outputs with --out");
  run->add_option("scene", a->scene,
                  "A built-in scene (`vrdeform scenes`) or a scene file (.toml); with --replay, the recording's");
  run->add_option("--substeps", a->substeps, "Override the scene's substeps")->check(CLI::Range(1, 1000));
  run->add_option("--iterations", a->iterations, "Override the scene's iterations")->check(CLI::Range(1, 1000));
  addRunOptions(*run, a->run);
  CLI::App* scenes = app.add_subcommand("scenes", "List the built-in scenes");
  return [a, run, scenes]() -> int {
    if (*run) return vrd::run(*a);
    if (*scenes) return listScenes();
    return 0;
  };
}

}  // namespace vrd
