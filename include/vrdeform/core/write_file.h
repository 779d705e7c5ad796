#pragma once
// Writing a whole text file, complete or not at all (a temporary renamed into place).

#include <filesystem>
#include <string_view>

namespace vrd {

/// Writes `text` to `path`; on any failure throws vrd::Error and leaves no partial file behind.
void writeFile(const std::filesystem::path& path, std::string_view text);

}  // namespace vrd
