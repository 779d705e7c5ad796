// The scene fuzz target's corpus (tests/fuzz_corpus/scene): the seeds (the scenes/ files) parse, and
// the inputs the fuzzer found (bad_*) are refused with a vrd::Error. Paths are relative to scenes/,
// as in the fuzz target.
#include <gtest/gtest.h>

#include "fuzz_corpus.h"
#include "vrdeform/scene/scene_file.h"

namespace vrd {
namespace {

TEST(FuzzCorpus, Scene) {
  const std::filesystem::path scenes = std::filesystem::path(VRDEFORM_TEST_DATA_DIR) / ".." / "scenes";
  testing::checkCorpus("scene", [&](std::string_view text) { parseScene(text, "corpus.toml", scenes); });
}

}  // namespace
}  // namespace vrd
