#pragma once
// File formats follow the extension, in any letter case.

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

namespace vrd::io {

inline std::string lowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

}  // namespace vrd::io
