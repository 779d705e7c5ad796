#include "view_command.h"

#include <memory>

#include "scene_video.h"
#include "viewer/viewer.h"
#include "vrdeform/devices/glove_link.h"

namespace vrd {

std::function<int()> addViewCommand(CLI::App& app) {
  auto o = std::make_shared<ViewerOptions>();
  CLI::App* cmd = app.add_subcommand("view", "Open the desktop viewer on a scene: poke and pinch it with the mouse");
  cmd->add_option("scene", o->scene, "A built-in scene (`vrdeform scenes`) or a scene file (.toml)")
      ->capture_default_str();
  auto* frames = cmd->add_option("--frames", o->frames, "Quit after drawing this many frames (tests, screenshots)")
                     ->check(CLI::Range(1, 100000000));
  cmd->add_option("--seconds", o->seconds, "Quit after this many seconds (wall clock)")->check(CLI::Range(1e-3, 1e9));
  cmd->add_option("--screenshot", o->screenshot, "Write the last frame's 3D view to this PNG file (needs --frames)")
      ->needs(frames);  // the last frame is known only then
  cmd->add_option("--weart", o->weart,
                  "Drive the hand from a WEART glove and send it the forces: HOST[:PORT] of the middleware (default "
                  "port 13031)")
      ->check(CLI::Validator(weartEndpointError, "HOST[:PORT]"));
  addColorMapOption(*cmd, o->colorMap);
  cmd->add_option("--width", o->width, "Window width in pixels")->check(CLI::Range(320, 8192))->capture_default_str();
  cmd->add_option("--height", o->height, "Window height in pixels")
      ->check(CLI::Range(240, 8192))
      ->capture_default_str();
  return [o, cmd]() -> int { return *cmd ? runViewer(*o) : 0; };
}

}  // namespace vrd
