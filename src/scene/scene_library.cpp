#include "vrdeform/scene/scene_library.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>

#include "vrdeform/core/installed_data.h"
#include "vrdeform/error.h"
#include "vrdeform/scene/scene_file.h"

namespace vrd {

namespace fs = std::filesystem;

fs::path sceneFolder() {
  if (const char* env = std::getenv("VRDEFORM_SCENES"); env && *env) {
    if (!fs::is_directory(env)) throw Error(fmt::format("VRDEFORM_SCENES={}: not a folder", env));
    return env;
  }
  std::error_code ec;
  for (const fs::path& dir : {fs::path(VRDEFORM_SOURCE_SCENES), installedData("scenes")})
    if (!dir.empty() && fs::is_directory(dir, ec)) return dir;
  throw Error(fmt::format("the built-in scenes are missing (looked in {} and {}); set VRDEFORM_SCENES to their folder",
                          VRDEFORM_SOURCE_SCENES, installedData("scenes").string()));
}

std::vector<SceneEntry> builtinScenes() {
  std::vector<SceneEntry> scenes;
  for (const fs::directory_entry& e : fs::directory_iterator(sceneFolder()))
    if (e.path().extension() == ".toml") scenes.push_back({e.path().stem().string(), e.path()});
  std::sort(scenes.begin(), scenes.end(), [](const SceneEntry& a, const SceneEntry& b) { return a.name < b.name; });
  return scenes;
}

SceneSpec loadSceneByName(std::string_view nameOrPath) {
  const std::string s(nameOrPath);
  if (s.find('/') != std::string::npos || fs::path(s).extension() == ".toml") return loadScene(s);
  std::string names;
  for (const SceneEntry& e : builtinScenes()) {
    if (e.name == s) return loadScene(e.file);
    names += (names.empty() ? "" : ", ") + e.name;
  }
  throw Error(
      fmt::format("no built-in scene '{}' (there are: {}); a scene file needs a '/' or a .toml ending", s, names));
}

}  // namespace vrd
