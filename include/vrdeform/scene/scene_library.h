#pragma once
// The built-in scenes: the paper's six (fur ball, liver, balloon, jelly, bear toy, flag) as scene
// files shipped with vrdeform, found by name.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "vrdeform/scene/scene_spec.h"

namespace vrd {

struct SceneEntry {
  std::string name;  ///< what `vrdeform run NAME` takes
  std::filesystem::path file;
};

/// The folder the built-in scenes are read from: $VRDEFORM_SCENES if set, else the source tree's
/// scenes/ (a build), else <prefix>/share/vrdeform/scenes next to the installed program.
/// Throws vrd::Error when none exists.
std::filesystem::path sceneFolder();

/// The built-in scenes (the .toml files of sceneFolder()), sorted by name.
std::vector<SceneEntry> builtinScenes();

/// A built-in scene's name, or the path of a scene file (anything with a '/' or a .toml ending).
/// Throws vrd::Error naming the built-in scenes for an unknown name.
SceneSpec loadSceneByName(std::string_view nameOrPath);

}  // namespace vrd
