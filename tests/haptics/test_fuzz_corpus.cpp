// The hand script and session recording fuzz targets' corpora (tests/fuzz_corpus/hand_script and
// session_recording): the seeds parse, and the inputs the fuzzers found (bad_*) are refused with a
// vrd::Error.
#include <gtest/gtest.h>

#include "fuzz_corpus.h"
#include "vrdeform/interact/hand_script.h"
#include "vrdeform/interact/session_recording.h"

namespace vrd {
namespace {

TEST(FuzzCorpus, HandScript) {
  testing::checkCorpus("hand_script", [](std::string_view text) { HandScript::parse(text, "corpus.hand"); });
}

TEST(FuzzCorpus, SessionRecording) {
  testing::checkCorpus("session_recording",
                       [](std::string_view text) { SessionRecording::parse(text, "corpus.session"); });
}

}  // namespace
}  // namespace vrd
