#pragma once
// What the fuzz targets share: a broken promise is a finding (require), the input as text, and a
// scratch file for readers that take a path.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace vrd::fuzz {

// A broken invariant stops the run with the input saved, as a crash does.
inline void require(bool ok) {
  if (!ok) __builtin_trap();
}

inline std::string_view text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// One file per process (so that parallel fuzzers do not share it) under $TMPDIR, removed at exit.
class ScratchFile {
 public:
  explicit ScratchFile(std::string_view extension)
      : path_(std::filesystem::temp_directory_path() /
              ("vrdeform_fuzz_" + std::to_string(::getpid()) + std::string(extension))) {}
  ~ScratchFile() {
    std::error_code ec;
    std::filesystem::remove(path_, ec);
  }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;

  const std::filesystem::path& write(std::string_view bytes) const {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    require(out.good());
    return path_;
  }

 private:
  std::filesystem::path path_;
};

}  // namespace vrd::fuzz
