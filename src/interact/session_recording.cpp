#include "vrdeform/interact/session_recording.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>

#include "vrdeform/core/atomic_file.h"
#include "vrdeform/core/text_tokens.h"
#include "vrdeform/error.h"

namespace vrd {
namespace {

constexpr std::string_view kSessionTag = "vrdeform-session";
constexpr std::int64_t kSessionVersion = 1;
constexpr std::string_view kSetting = "setting";
constexpr std::string_view kEnd = "end";
// Fields of a step line before its outputs: index, direct, wrist 3x4, closures, fingertips, count.
constexpr std::size_t kWrist = 2, kClosure = kWrist + 12, kTips = kClosure + kFingerCount,
                      kCount = kTips + 3 * kFingerCount, kFixedFields = kCount + 1;
constexpr const char* kStepLayout =
    "step direct  wrist 3x4 row by row (m)  closures thumb..little  fingertips 5 x (x y z) (m)  output-count outputs";

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

// Hexadecimal floats (C's %a): exact in both directions. Infinities are written "inf"/"-inf", NaN
// "nan"/"-nan" (sign kept, payload not).
void appendFloat(std::string& out, float v) {
  if (std::isnan(v)) {
    out += std::signbit(v) ? "-nan" : "nan";
    return;
  }
  if (std::signbit(v)) out += '-';
  if (std::isinf(v)) {
    out += "inf";
    return;
  }
  out += "0x";
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, std::abs(v), std::chars_format::hex);
  out.append(buffer, result.ptr);
}

bool parseHexFloat(std::string_view token, float& value) {
  const bool negative = !token.empty() && token.front() == '-';
  if (negative) token.remove_prefix(1);
  float magnitude = 0;
  if (token == "inf") {
    magnitude = std::numeric_limits<float>::infinity();
  } else if (token == "nan") {
    magnitude = std::numeric_limits<float>::quiet_NaN();
  } else {
    if (token.size() < 3 || token[0] != '0' || (token[1] != 'x' && token[1] != 'X')) return false;
    token.remove_prefix(2);
    // A digit first (no second sign, no "0xinf"), and an exponent: a number cut short must not
    // read as a different one.
    if (!std::isxdigit(static_cast<unsigned char>(token[0])) || token.find_first_of("pP") == std::string_view::npos)
      return false;
    const char* end = token.data() + token.size();
    const auto [stop, ec] = std::from_chars(token.data(), end, magnitude, std::chars_format::hex);
    if (ec != std::errc() || stop != end) return false;
  }
  value = negative ? -magnitude : magnitude;
  return true;
}

// Bytes a setting may hold: printable ASCII and UTF-8 continuation/lead bytes; never a line break.
bool settingByte(unsigned char c, bool spaceAllowed) { return (c > 0x20 && c != 0x7f) || (spaceAllowed && c == ' '); }

// What keeps `key`/`value` from being written and read back as they are, or "".
std::string settingProblem(std::string_view key, std::string_view value) {
  if (key.empty()) return "the key is empty";
  for (unsigned char c : key)
    if (!settingByte(c, false)) return fmt::format("the key contains byte 0x{:02x} (a space or control character)", c);
  for (unsigned char c : value)
    if (!settingByte(c, true)) return fmt::format("the value contains control byte 0x{:02x}", c);
  if (!value.empty() && (value.front() == ' ' || value.back() == ' '))
    return "the value starts or ends with a space, which would not be read back";
  return {};
}

// One step line; `index` is the step it must be.
RecordedStep parseStep(const std::vector<std::string_view>& t, std::size_t index, const io::TextTokens& lines) {
  if (t.size() < kFixedFields)
    lines.fail(fmt::format("a step line has at least {} fields ({}), found {}: truncated?", kFixedFields, kStepLayout,
                           t.size()));
  std::int64_t number = -1;
  if (!io::parseInteger(t[0], number) || number < 0)
    lines.fail(fmt::format("expected a step number, found '{}'", io::printable(t[0])));
  if (static_cast<std::uint64_t>(number) != index)
    lines.fail(
        fmt::format("step {} where step {} was expected: steps are numbered 0, 1, 2, ... in order", number, index));
  RecordedStep step;
  if (t[1] != "0" && t[1] != "1")
    lines.fail(fmt::format("step {}: 'direct' is 0 or 1, found '{}'", index, io::printable(t[1])));
  step.frame.direct = t[1] == "1";
  auto number32 = [&](std::size_t i) {
    float v = 0;
    if (!parseHexFloat(t[i], v))
      lines.fail(fmt::format("step {}, field {}: expected a hexadecimal float such as 0x1.8p+3, found '{}'", index,
                             i + 1, io::printable(t[i])));
    return v;
  };
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) step.frame.pose.wrist.matrix()(r, c) = number32(kWrist + 4 * r + c);
  for (int f = 0; f < kFingerCount; ++f) step.frame.pose.closure[f] = number32(kClosure + f);
  for (int f = 0; f < kFingerCount; ++f)
    for (int a = 0; a < 3; ++a) step.frame.fingertips[f][a] = number32(kTips + 3 * f + a);
  std::int64_t count = -1;
  if (!io::parseInteger(t[kCount], count) || count < 0)
    lines.fail(fmt::format("step {}: expected the output count, found '{}'", index, io::printable(t[kCount])));
  if (static_cast<std::uint64_t>(count) != t.size() - kFixedFields)
    lines.fail(fmt::format("step {} says {} outputs but has {}: truncated?", index, count, t.size() - kFixedFields));
  step.outputs.resize(static_cast<std::size_t>(count));
  for (std::size_t i = 0; i < step.outputs.size(); ++i) step.outputs[i] = number32(kFixedFields + i);
  return step;
}

}  // namespace

const std::string* SessionRecording::setting(std::string_view key) const {
  for (const auto& [k, v] : settings)
    if (k == key) return &v;
  return nullptr;
}

namespace {

void appendHeader(std::string& out, const std::vector<std::pair<std::string, std::string>>& settings) {
  fmt::format_to(std::back_inserter(out), "{} {}\n", kSessionTag, kSessionVersion);
  for (std::size_t i = 0; i < settings.size(); ++i) {
    const auto& [key, value] = settings[i];
    const std::string what = settingProblem(key, value);
    if (!what.empty()) throw Error(fmt::format("session recording: setting '{}': {}", io::printable(key), what));
    for (std::size_t j = 0; j < i; ++j)
      if (settings[j].first == key) throw Error(fmt::format("session recording: setting '{}' appears twice", key));
    fmt::format_to(std::back_inserter(out), "{} {}{}{}\n", kSetting, key, value.empty() ? "" : " ", value);
  }
  fmt::format_to(std::back_inserter(out), "# {}\n", kStepLayout);
}

void appendStep(std::string& out, std::uint64_t k, const RecordedStep& step) {
  const HandFrame& f = step.frame;
  fmt::format_to(std::back_inserter(out), "{} {}", k, f.direct ? 1 : 0);
  auto put = [&](float v) {
    out += ' ';
    appendFloat(out, v);
  };
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) put(f.pose.wrist.matrix()(r, c));
  for (float c : f.pose.closure) put(c);
  for (const Vec3& tip : f.fingertips)
    for (int a = 0; a < 3; ++a) put(tip[a]);
  fmt::format_to(std::back_inserter(out), " {}", step.outputs.size());
  for (float v : step.outputs) put(v);
  out += '\n';
}

void appendEnd(std::string& out, std::uint64_t steps) {
  fmt::format_to(std::back_inserter(out), "{} {}\n", kEnd, steps);
}

std::string header(const std::vector<std::pair<std::string, std::string>>& settings) {
  std::string out;
  appendHeader(out, settings);
  return out;
}

}  // namespace

std::string SessionRecording::format() const {
  std::string out = header(settings);
  for (std::size_t k = 0; k < steps.size(); ++k) appendStep(out, k, steps[k]);
  appendEnd(out, steps.size());
  return out;
}

SessionRecordingWriter::SessionRecordingWriter(const std::filesystem::path& path,
                                               const std::vector<std::pair<std::string, std::string>>& settings)
    : text_(header(settings)), file_(path) {
  file_.stream() << text_;
}

void SessionRecordingWriter::add(const RecordedStep& step) {
  text_.clear();
  appendStep(text_, steps_++, step);
  file_.stream() << text_;
}

void SessionRecordingWriter::finish() {
  text_.clear();
  appendEnd(text_, steps_);
  file_.stream() << text_;
  file_.commit();
}

void SessionRecording::save(const std::filesystem::path& path) const {
  const std::string text = format();  // may throw: before the file is touched
  AtomicFile file(path);
  file.stream().write(text.data(), static_cast<std::streamsize>(text.size()));
  file.commit();
}

SessionRecording SessionRecording::parse(std::string_view text, std::string_view sourceName) {
  // '#' starts a comment only at the start of a line: a setting's value may hold one.
  io::TextTokens lines(text, std::string(sourceName), '#');
  SessionRecording recording;
  std::vector<std::string_view> tokens;
  bool tagged = false, ended = false;
  while (!lines.atEnd()) {  // skips blank lines and comment lines
    const std::string_view line = lines.restOfLine();
    io::splitWords(line, tokens);
    if (tokens.empty()) continue;  // cannot happen after atEnd(), but costs nothing to be sure
    if (!tagged) {
      std::int64_t version = 0;
      if (tokens.size() != 2 || tokens[0] != kSessionTag || !io::parseInteger(tokens[1], version))
        lines.fail(fmt::format("not a session recording: expected '{} {}' first, found '{}'", kSessionTag,
                               kSessionVersion, io::printable(line)));
      if (version != kSessionVersion)
        lines.fail(fmt::format("unsupported {} version {} (this program reads version {})", kSessionTag, version,
                               kSessionVersion));
      tagged = true;
    } else if (ended) {
      lines.fail(fmt::format("'{}' found after the '{}' line", io::printable(line), kEnd));
    } else if (tokens[0] == kSetting) {
      if (!recording.steps.empty()) lines.fail("settings must come before the first step");
      if (tokens.size() < 2) lines.fail("a setting line is 'setting <key> <value>'; the key is missing");
      const std::string_view key = tokens[1];
      std::string_view value = line.substr(static_cast<std::size_t>(key.data() + key.size() - line.data()));
      while (!value.empty() && isSpace(value.front())) value.remove_prefix(1);
      while (!value.empty() && isSpace(value.back())) value.remove_suffix(1);
      const std::string what = settingProblem(key, value);
      if (!what.empty()) lines.fail(fmt::format("setting '{}': {}", io::printable(key), what));
      if (recording.setting(key)) lines.fail(fmt::format("setting '{}' appears twice", io::printable(key)));
      recording.settings.emplace_back(std::string(key), std::string(value));
    } else if (tokens[0] == kEnd) {
      std::int64_t count = -1;
      if (tokens.size() != 2 || !io::parseInteger(tokens[1], count))
        lines.fail(fmt::format("expected '{} <step count>'", kEnd));
      if (static_cast<std::uint64_t>(count) != recording.steps.size())
        lines.fail(fmt::format("'{}' says {} steps, but the file has {}", kEnd, count, recording.steps.size()));
      ended = true;
    } else {
      recording.steps.push_back(parseStep(tokens, recording.steps.size(), lines));
    }
  }
  if (!tagged) throw Error(fmt::format("{}:1: empty file, not a session recording", sourceName));
  if (!ended)
    lines.fail(fmt::format("the file ends without its '{} <step count>' line: truncated? ({} steps read)", kEnd,
                           recording.steps.size()));
  return recording;
}

SessionRecording SessionRecording::load(const std::filesystem::path& path) {
  return parse(io::readFileBytes(path), path.string());
}

HandFrame RecordingInput::frame(std::uint64_t step, double /*time*/) {
  const auto& steps = recording_.steps;
  if (steps.empty()) {
    HandFrame still;
    still.fingertips.fill(Vec3::Zero());  // Eigen leaves them uninitialised
    return still;
  }
  return steps[std::min<std::uint64_t>(step, steps.size() - 1)].frame;
}

bool RecordingInput::finished(std::uint64_t step, double /*time*/) const { return step >= recording_.steps.size(); }

}  // namespace vrd
