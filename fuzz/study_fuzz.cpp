// libFuzzer target for study files (parseStudy, docs/study.md): TOML from people's editors, read
// with the scene files' schema helpers. Scene paths are relative to the repository's studies/
// folder. A vrd::Error is the expected answer to bad input; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <filesystem>

#include "fuzz_support.h"
#include "vrdeform/error.h"
#include "vrdeform/study/study_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path base = std::filesystem::path(VRDEFORM_SOURCE_DIR) / "studies";
  try {
    vrd::parseStudy(vrd::fuzz::text(data, size), "fuzz.toml", base);
  } catch (const vrd::Error&) {
    // bad input, said so
  }
  return 0;
}
