// vrdeform: the command-line program.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "demo.h"
#include "mesh_commands.h"
#include "touch_command.h"
#include "vrdeform/error.h"

int main(int argc, char** argv) {
  CLI::App app{"vrdeform: real-time visual and haptic interaction with deformable bodies (XPBD)"};
  app.set_version_flag("--version", "vrdeform 0.1.0");
  app.require_subcommand(1);

  vrd::DemoOptions demo;
  CLI::App* run = app.add_subcommand("run", "Simulate the built-in demo headless and print what happened");
  run->add_option("--seconds", demo.seconds, "Simulated time")->check(CLI::Range(0.0f, 3600.0f))->capture_default_str();
  run->add_option("--substeps", demo.substeps, "Substeps per 1/60 s step")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  run->add_option("--iterations", demo.iterations, "Gauss-Seidel iterations per substep")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  run->add_option("--tets", demo.tets, "Approximate number of tetrahedra")
      ->check(CLI::Range(6, 2000000))
      ->capture_default_str();
  run->add_option("--report-every", demo.reportEvery, "Seconds between timeline rows")
      ->check(CLI::Range(0.001f, 3600.0f))
      ->capture_default_str();

  run->add_option("--save", demo.savePath, "Save the deforming body for ParaView: a .pvd plus one .vtu per frame");
  run->add_option("--save-every", demo.saveEvery, "Seconds between saved frames")
      ->check(CLI::Range(0.001f, 3600.0f))
      ->capture_default_str();

  const auto runMeshCommand = vrd::addMeshCommands(app);
  const auto runTouchCommand = vrd::addTouchCommand(app);

  CLI11_PARSE(app, argc, argv);
  try {
    if (*run) return vrd::runDemo(demo);
    if (app.got_subcommand("mesh")) return runMeshCommand();
    if (app.got_subcommand("touch")) return runTouchCommand();
  } catch (const vrd::Error& e) {
    fmt::print(stderr, "vrdeform: {}\n", e.what());
    return 2;
  }
  return 0;
}
