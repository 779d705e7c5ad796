// The scene and study fuzz targets' corpora (tests/fuzz_corpus/scene, .../study): the seeds (the
// scenes/ files, studies/paper.toml) parse, and the bad inputs (bad_*) are refused with a
// vrd::Error. Paths are relative to scenes/ and studies/, as in the fuzz targets.
#include <gtest/gtest.h>

#include "fuzz_corpus.h"
#include "vrdeform/scene/scene_file.h"
#include "vrdeform/study/study_file.h"

namespace vrd {
namespace {

TEST(FuzzCorpus, Scene) {
  const std::filesystem::path scenes = std::filesystem::path(VRDEFORM_TEST_DATA_DIR) / ".." / "scenes";
  testing::checkCorpus("scene", [&](std::string_view text) { parseScene(text, "corpus.toml", scenes); });
}

TEST(FuzzCorpus, Study) {
  const std::filesystem::path studies = std::filesystem::path(VRDEFORM_TEST_DATA_DIR) / ".." / "studies";
  testing::checkCorpus("study", [&](std::string_view text) { parseStudy(text, "corpus.toml", studies); });
}

}  // namespace
}  // namespace vrd
