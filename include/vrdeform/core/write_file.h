#pragma once
// Writing a whole text file, complete or not at all (a temporary renamed into place), and a folder
// for a command's outputs.

#include <filesystem>
#include <string_view>

namespace vrd {

/// Writes `text` to `path`; on any failure throws vrd::Error and leaves no partial file behind.
void writeFile(const std::filesystem::path& path, std::string_view text);

/// Makes the folder `dir` (and its parents) and checks that a file can be written in it; throws
/// vrd::Error saying why not. A command calls it before its work, not after.
void prepareOutputFolder(const std::filesystem::path& dir);

}  // namespace vrd
