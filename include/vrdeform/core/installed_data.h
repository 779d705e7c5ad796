#pragma once

#include <filesystem>
#include <string_view>

namespace vrd {

/// <prefix>/share/vrdeform/`name` for this program installed as <prefix>/bin/PROGRAM: where the
/// installed built-in scenes and VR page live; empty when the program's path is unknown.
std::filesystem::path installedData(std::string_view name);

}  // namespace vrd
