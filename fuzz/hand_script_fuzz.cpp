// libFuzzer target for hand scripts (HandScript::parse, docs/hand-input.md). A vrd::Error is the
// expected answer to bad input; besides crashes, sanitizer reports and leaks, a finding is a script
// that parses but does not read back as itself (parse(format()) must give the same keyframes) or
// that samples to a non-finite hand.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "fuzz_support.h"
#include "vrdeform/error.h"
#include "vrdeform/interact/hand_script.h"

namespace {

using namespace vrd;
using fuzz::require;

bool finite(const HandPose& pose) {
  if (!pose.wrist.matrix().allFinite()) return false;
  for (float c : pose.closure)
    if (!std::isfinite(c)) return false;
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const HandScript script = HandScript::parse(fuzz::text(data, size), "fuzz.hand");
    const std::string text = script.format();
    const HandScript back = HandScript::parse(text, "formatted.hand");
    require(back.format() == text && back.keyframes().size() == script.keyframes().size());
    const double first = script.keyframes().front().time, last = script.duration();
    for (const double t :
         {first - 1.0, first, 0.5 * (first + last), last, last + 1.0, std::numeric_limits<double>::quiet_NaN()})
      require(finite(script.sample(t)));
  } catch (const Error&) {
    // bad input, said so
  }
  return 0;
}
