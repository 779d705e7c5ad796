// The study fuzz target's corpus (tests/fuzz_corpus/study): the seed (studies/paper.toml) parses,
// the bad inputs are refused with a vrd::Error. Paths are relative to studies/, as in the target.
#include <gtest/gtest.h>

#include "fuzz_corpus.h"
#include "vrdeform/study/study_file.h"

namespace vrd {
namespace {

TEST(FuzzCorpus, Study) {
  const std::filesystem::path studies = std::filesystem::path(VRDEFORM_TEST_DATA_DIR) / ".." / "studies";
  testing::checkCorpus("study", [&](std::string_view text) { parseStudy(text, "corpus.toml", studies); });
}

}  // namespace
}  // namespace vrd
