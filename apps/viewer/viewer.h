#pragma once
// The desktop viewer (`vrdeform view`): a GLFW window drawing a scene at the display's rate while
// its SimulationLoop runs on its own thread at the scene's rate. The window reads the loop's
// snapshots only; the mouse (or a WEART glove) drives the hand through a wait-free handoff; Dear
// ImGui panels pick the scene, pause and step, change the solver live and the materials and
// haptic parameters by rebuilding the scene, and show the per-finger forces, stage times and
// volume loss (docs/viewer.md). For `vrdeform study run` it walks a participant through a study
// instead: instructions, trials, rests and the questionnaire, with the developer's panels hidden.

#include <string>

#include "vrdeform/render/posed_scene.h"

namespace vrd {

class ParticipantProgress;

struct ViewerOptions {
  std::string scene = "liver";  ///< a built-in scene or a scene file
  int frames = 0;               ///< quit after this many frames; 0: when the window closes
  double seconds = 0.0;         ///< quit after this much wall time; 0: when the window closes
  std::string screenshot;       ///< write the 3D view of the last frame here (PNG)
  std::string weart;            ///< HOST[:PORT] of the WEART middleware; empty: the mouse is the hand
  int width = 1280, height = 800;
  ColorMap colorMap = ColorMap::None;
  ParticipantProgress* study = nullptr;  ///< walk this participant through their study (`scene` unused)
  bool autopilot =
      false;  ///< with `study`: each step starts and is answered by itself, the scenes' scripted hands poke
};

/// Opens the window and runs until it closes (or `frames` are drawn, or a study's participant is
/// done). Returns 0, or 1 when no window can be opened (no display) or the simulation failed;
/// throws vrd::Error for bad input.
int runViewer(const ViewerOptions& options);

}  // namespace vrd
