#pragma once
// Scene files: TOML with the schema of docs/scenes.md, read into a SceneSpec.

#include <filesystem>
#include <string_view>

#include "vrdeform/scene/scene_spec.h"

namespace vrd {

/// Parses a scene. Relative mesh and script paths are taken from `baseDir` and made absolute, and
/// must name existing files. Every problem throws vrd::Error as "SOURCE:LINE: KEY: what", with KEY
/// the dotted path of the offending key (e.g. `body[2].material.youngs`, indices from 1): a TOML
/// syntax error, an unknown key, a wrong type, a missing required key, a value out of range, a
/// missing file. The scene's `source` is `sourceName`, and its name defaults to the stem of it.
SceneSpec parseScene(std::string_view text, std::string_view sourceName, const std::filesystem::path& baseDir);

/// Reads and parses a scene file (paths relative to its folder); messages name the file as `path`
/// is written, and `source` is its absolute path. Throws vrd::Error, "PATH: cannot read: why" for
/// a file it cannot read.
SceneSpec loadScene(const std::filesystem::path& path);

/// The scene of a file that says only `[[body]] mesh = "MESH"`: the mesh (relative to the current
/// folder) on the ground with the scene files' defaults (soft tissue, settled to rest, the hand).
/// Named after the mesh's stem; throws vrd::Error as parseScene does.
SceneSpec sceneOfMesh(const std::filesystem::path& mesh);

}  // namespace vrd
