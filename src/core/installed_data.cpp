#include "vrdeform/core/installed_data.h"

#include <unistd.h>

#include <array>
#include <string>

namespace vrd {

std::filesystem::path installedData(std::string_view name) {
  std::array<char, 4096> buffer{};
  const ssize_t n = ::readlink("/proc/self/exe", buffer.data(), buffer.size() - 1);
  if (n <= 0) return {};
  const std::filesystem::path program(std::string(buffer.data(), std::size_t(n)));
  return program.parent_path().parent_path() / "share" / "vrdeform" / name;
}

}  // namespace vrd
