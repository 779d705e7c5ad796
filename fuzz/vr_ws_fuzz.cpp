// libFuzzer target for what a VR page sends over its WebSocket (vr::parseClientMessage,
// docs/vr.md#client-messages), handled as the server's Viewer::handle does: an input becomes the
// hand (xrHandFrame), a ping a pong, a rejected message an error reply naming the reason. A
// vrd::Error is the expected answer to bad input; any other exception (JSON's own, e.g. a reply
// that cannot be written), a crash, a sanitizer report or a leak is a finding, and so is an
// accepted input whose hand is not finite (a tracked hand's untracked tips excepted: NaN).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "fuzz_support.h"
#include "vrdeform/error.h"
#include "vrdeform/web/vr_protocol.h"
#include "vrdeform/web/xr_hand.h"

namespace {

using namespace vrd;
using fuzz::require;

void checkHand(const XrInput& input) {
  const HandFrame frame = xrHandFrame(input, XrHandSettings{}, 0.008f);
  for (const Vec3& tip : frame.fingertips)
    for (int k = 0; k < 3; ++k)
      require(std::isfinite(tip[k]) || (input.source == XrSource::Hand && std::isnan(tip[k])));
  require(frame.pose.wrist.matrix().allFinite());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using json = nlohmann::json;
  vr::ClientMessage m;
  try {
    m = vr::parseClientMessage(fuzz::text(data, size));
  } catch (const Error& e) {
    (void)json{{"type", "error"}, {"reason", e.what()}}.dump();  // the server's reply
    return 0;
  }
  switch (m.type) {
    case vr::ClientMessage::Type::Input:
      checkHand(m.input);
      break;
    case vr::ClientMessage::Type::Ping:
      require(std::isfinite(m.pingTime));
      (void)json{{"type", "pong"}, {"t", m.pingTime}, {"step", 0}}.dump();
      break;
    case vr::ClientMessage::Type::Hello:
      require(m.client.size() <= 64);
      (void)json{{"client", m.client}}.dump();  // valid UTF-8, however it was cut
      break;
    case vr::ClientMessage::Type::Study:
      require(m.study.ratings.size() <= vr::kMaxStudyItems && m.study.texts.size() <= vr::kMaxStudyItems);
      for (const std::string& t : m.study.texts) require(t.size() <= vr::kMaxStudyTextBytes);
      break;
  }
  return 0;
}
