// vrdeform: the command-line program.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "bench_command.h"
#include "mesh_commands.h"
#include "render_command.h"
#include "run_command.h"
#include "serve_command.h"
#include "soak_command.h"
#include "study_command.h"
#include "touch_command.h"
#include "view_command.h"
#include "vrdeform/error.h"

int main(int argc, char** argv) {
  CLI::App app{"vrdeform: real-time visual and haptic interaction with deformable bodies (XPBD)"};
  app.set_version_flag("--version", "vrdeform 0.1.0");
  app.require_subcommand(1);

  const auto runRunCommand = vrd::addRunCommands(app);
  const auto runMeshCommand = vrd::addMeshCommands(app);
  const auto runTouchCommand = vrd::addTouchCommand(app);
  const auto runBenchCommand = vrd::addBenchCommand(app);
  const auto runRenderCommand = vrd::addRenderCommand(app);
  const auto runViewCommand = vrd::addViewCommand(app);
  const auto runServeCommand = vrd::addServeCommand(app);
  const auto runSoakCommand = vrd::addSoakCommand(app);
  const auto runStudyCommand = vrd::addStudyCommand(app);

  // Exit status: 0 fine; 1 a run failed part-way, a mesh has defects or a replay differs; 2 bad
  // input, usage errors included (CLI11's own codes are folded into 2); 130 stopped by Ctrl-C (or
  // SIGTERM) before its run began (meshing, settling, calibrating).
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    if (app.got_subcommand("run") || app.got_subcommand("scenes")) return runRunCommand();
    if (app.got_subcommand("mesh")) return runMeshCommand();
    if (app.got_subcommand("touch")) return runTouchCommand();
    if (app.got_subcommand("bench")) return runBenchCommand();
    if (app.got_subcommand("render")) return runRenderCommand();
    if (app.got_subcommand("view")) return runViewCommand();
    if (app.got_subcommand("serve")) return runServeCommand();
    if (app.got_subcommand("soak")) return runSoakCommand();
    if (app.got_subcommand("study")) return runStudyCommand();
  } catch (const vrd::Error& e) {
    fmt::print(stderr, "vrdeform: {}\n", e.what());
    return 2;
  } catch (const vrd::Stopped& e) {
    fmt::print(stderr, "\nvrdeform: {}\n", e.what());
    return 130;
  }
  return 0;
}
