// libFuzzer target for session recordings (SessionRecording::parse, docs/hand-input.md). A
// vrd::Error is the expected answer to bad input; besides crashes, sanitizer reports and leaks, a
// finding is a recording that parses but cannot be written, or is not written the same way after
// reading its own text back.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_support.h"
#include "vrdeform/error.h"
#include "vrdeform/interact/session_recording.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace vrd;
  SessionRecording recording;
  try {
    recording = SessionRecording::parse(fuzz::text(data, size), "fuzz.session");
  } catch (const Error&) {
    return 0;  // bad input, said so
  }
  // What parse accepted, format must write (it throws for settings that would not read back).
  const std::string text = recording.format();
  const SessionRecording back = SessionRecording::parse(text, "formatted.session");
  fuzz::require(back.format() == text && back.steps.size() == recording.steps.size() &&
                back.settings == recording.settings);
  return 0;
}
