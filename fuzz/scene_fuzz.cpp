// libFuzzer target for scene files (parseScene, docs/scenes.md): TOML from people's editors. Paths
// are relative to the repository's scenes/ folder, so the seeds' meshes exist. A vrd::Error is the
// expected answer to bad input; any other exception (toml++'s own included), a crash, a sanitizer
// report or a leak is a finding.
#include <cstddef>
#include <cstdint>
#include <filesystem>

#include "fuzz_support.h"
#include "vrdeform/error.h"
#include "vrdeform/scene/scene_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path base = std::filesystem::path(VRDEFORM_SOURCE_DIR) / "scenes";
  try {
    vrd::parseScene(vrd::fuzz::text(data, size), "fuzz.toml", base);
  } catch (const vrd::Error&) {
    // bad input, said so
  }
  return 0;
}
