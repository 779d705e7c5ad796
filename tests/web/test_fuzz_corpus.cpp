// The VR server's WebSocket fuzz target's corpus (tests/fuzz_corpus/vr_ws): the seeds parse, and the
// inputs the fuzzer found (bad_*) are refused with a vrd::Error whose reason the server can send back
// as JSON (a name quoted from the page is cut between UTF-8 characters, not inside one).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "fuzz_corpus.h"
#include "vrdeform/web/vr_protocol.h"

namespace vrd {
namespace {

// A JSON object as the server writes it, which throws for a string that is not valid UTF-8.
std::string jsonObject(const std::string& key, const std::string& value) { return nlohmann::json{{key, value}}.dump(); }

TEST(FuzzCorpus, VrClientMessages) {
  testing::checkCorpus("vr_ws", [](std::string_view text) {
    try {
      const vr::ClientMessage m = vr::parseClientMessage(text);
      EXPECT_LE(m.client.size(), 64u);
      EXPECT_NO_THROW(jsonObject("client", m.client));  // cut between characters
    } catch (const Error& e) {
      EXPECT_NO_THROW(jsonObject("reason", e.what()));  // the error reply
      throw;
    }
  });
}

}  // namespace
}  // namespace vrd
