#include "vrdeform/interact/hand_script.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

#include "vrdeform/core/atomic_file.h"
#include "vrdeform/core/text_tokens.h"
#include "vrdeform/error.h"

namespace vrd {
namespace {

constexpr std::string_view kTag = "vrdeform-hand-script";
constexpr std::int64_t kVersion = 1;
constexpr const char* kField[] = {"time", "x",     "y",     "z",      "qw",   "qx",    "qy",
                                  "qz",   "thumb", "index", "middle", "ring", "little"};
constexpr const char* kLayout = "time  x y z  qw qx qy qz  thumb index middle [ring little]";

// Straight to float (correctly rounded), so that a float written shortest reads back to its bits;
// through a double only when out of float range (overflow becomes infinity, rejected later).
bool parseFloat(std::string_view token, float& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto [stop, ec] = std::from_chars(token.data(), end, value);
  if (stop != end) return false;
  if (ec == std::errc::result_out_of_range) {
    double wide = 0;
    if (!io::parseReal(token, wide)) return false;
    if (std::abs(wide) > std::numeric_limits<float>::max())
      value = wide < 0 ? -HUGE_VALF : HUGE_VALF;
    else
      value = static_cast<float>(wide);
    return true;
  }
  return ec == std::errc();
}

// A unit quaternion, or false for one of zero or non-finite length. One already unit to float
// precision is kept as it is: normalising again could move its last bit, and saving then loading a
// script must change nothing.
bool normalise(Quat& q) {
  const double w = q.w(), x = q.x(), y = q.y(), z = q.z();
  const double n2 = w * w + x * x + y * y + z * z;
  if (!std::isfinite(n2) || !(n2 > 1e-12)) return false;
  if (std::abs(n2 - 1.0) > 1e-6) {
    const double s = 1.0 / std::sqrt(n2);
    q = Quat(static_cast<float>(w * s), static_cast<float>(x * s), static_cast<float>(y * s),
             static_cast<float>(z * s));
  }
  return true;
}

// What is wrong with `k` after `previous` (null for the first keyframe), or "" when nothing is.
// Normalises k's orientation.
std::string problem(HandKeyframe& k, const HandKeyframe* previous) {
  if (!std::isfinite(k.time)) return fmt::format("time {} is not finite", k.time);
  if (previous && !(k.time > previous->time))
    return fmt::format("time {} is not after the previous keyframe's {}; times must increase", k.time, previous->time);
  if (!isFinite(k.position)) return "wrist position is not finite";
  if (!normalise(k.orientation))
    return fmt::format("orientation ({} {} {} {}) is not a rotation: its length is zero or not finite",
                       k.orientation.w(), k.orientation.x(), k.orientation.y(), k.orientation.z());
  for (int f = 0; f < kFingerCount; ++f)
    if (!(k.closure[f] >= 0.0f && k.closure[f] <= 1.0f))
      return fmt::format("{} closure {} is outside [0, 1]", kField[8 + f], k.closure[f]);
  return {};
}

HandPose poseOf(const HandKeyframe& k) {
  HandPose pose;
  pose.wrist.linear() = k.orientation.toRotationMatrix();
  pose.wrist.translation() = k.position;
  pose.closure = k.closure;
  return pose;
}

// The keyframe on one line, its fields as parsed; throws through `lines` for anything malformed.
HandKeyframe parseKeyframe(const std::vector<std::string_view>& tokens, const io::TextTokens& lines) {
  if (tokens.size() != 11 && tokens.size() != 13)
    lines.fail(fmt::format("a keyframe has 11 or 13 fields ({}), found {}", kLayout, tokens.size()));
  double time = 0;
  if (!io::parseReal(tokens[0], time)) lines.fail(fmt::format("time is not a number: '{}'", io::printable(tokens[0])));
  if (!std::isfinite(time)) lines.fail(fmt::format("time is {}; numbers must be finite", time));
  std::array<float, 13> v{};
  for (std::size_t i = 1; i < tokens.size(); ++i) {
    if (!parseFloat(tokens[i], v[i]))
      lines.fail(fmt::format("{} is not a number: '{}'", kField[i], io::printable(tokens[i])));
    if (!std::isfinite(v[i]))
      lines.fail(fmt::format("{} is {}; numbers must be finite", kField[i], io::printable(tokens[i])));
  }
  if (tokens.size() == 11) v[11] = v[12] = v[10];  // ring and little follow the middle finger
  HandKeyframe k;
  k.time = time;
  k.position = Vec3(v[1], v[2], v[3]);
  k.orientation = Quat(v[4], v[5], v[6], v[7]);
  std::copy(v.begin() + 8, v.end(), k.closure.begin());
  return k;
}

}  // namespace

HandScript::HandScript(std::vector<HandKeyframe> keyframes) : keyframes_(std::move(keyframes)) {
  if (keyframes_.empty()) throw Error("hand script: no keyframes");
  for (std::size_t i = 0; i < keyframes_.size(); ++i) {
    const std::string what = problem(keyframes_[i], i > 0 ? &keyframes_[i - 1] : nullptr);
    if (!what.empty()) throw Error(fmt::format("hand script keyframe {}: {}", i, what));
  }
}

HandScript HandScript::parse(std::string_view text, std::string_view sourceName) {
  io::TextTokens lines(text, std::string(sourceName), '#');
  std::vector<HandKeyframe> keyframes;
  bool first = true;
  while (!lines.atEnd()) {  // skips blank lines and comments
    std::string_view line = lines.restOfLine();
    line = line.substr(0, line.find('#'));
    std::vector<std::string_view> tokens;
    io::splitWords(line, tokens);
    if (tokens.empty()) continue;  // cannot happen after atEnd(), but costs nothing to be sure
    if (tokens.front() == kTag) {
      if (!first) lines.fail(fmt::format("'{}' (the format tag) may only be the first line", kTag));
      std::int64_t version = 0;
      if (tokens.size() != 2 || !io::parseInteger(tokens[1], version))
        lines.fail(fmt::format("expected '{} {}'", kTag, kVersion));
      if (version != kVersion)
        lines.fail(fmt::format("unsupported {} version {} (this program reads version {})", kTag, version, kVersion));
    } else {
      HandKeyframe k = parseKeyframe(tokens, lines);
      const std::string what = problem(k, keyframes.empty() ? nullptr : &keyframes.back());
      if (!what.empty()) lines.fail(what);
      keyframes.push_back(k);
    }
    first = false;
  }
  if (keyframes.empty()) {
    const auto lineCount = std::count(text.begin(), text.end(), '\n') + (text.empty() || text.back() != '\n');
    throw Error(fmt::format("{}:{}: no keyframes (a keyframe line is: {})", sourceName, lineCount, kLayout));
  }
  return HandScript(std::move(keyframes), Checked{});
}

HandScript HandScript::load(const std::filesystem::path& path) { return parse(io::readFileBytes(path), path.string()); }

std::string HandScript::format() const {
  std::string out = fmt::format("{} {}\n# {}\n", kTag, kVersion, kLayout);
  for (const HandKeyframe& k : keyframes_) {
    // Shortest representations that read back to the same double / float.
    fmt::format_to(std::back_inserter(out), "{}  {} {} {}  {} {} {} {}  {} {} {} {} {}\n", k.time, k.position.x(),
                   k.position.y(), k.position.z(), k.orientation.w(), k.orientation.x(), k.orientation.y(),
                   k.orientation.z(), k.closure[0], k.closure[1], k.closure[2], k.closure[3], k.closure[4]);
  }
  return out;
}

void HandScript::save(const std::filesystem::path& path) const {
  AtomicFile file(path);
  file.stream() << format();
  file.commit();
}

HandPose HandScript::sample(double t) const {
  const auto after = std::upper_bound(keyframes_.begin(), keyframes_.end(), t,
                                      [](double time, const HandKeyframe& k) { return time < k.time; });
  if (std::isnan(t) || after == keyframes_.begin()) return poseOf(keyframes_.front());
  const HandKeyframe& a = *(after - 1);
  if (after == keyframes_.end() || t == a.time) return poseOf(a);  // exactly the keyframe, no rounding
  const HandKeyframe& b = *after;
  double u = (t - a.time) / (b.time - a.time);
  if (!(u >= 0.0)) u = 0.0;  // inf / inf when the times are near the ends of the double range
  const float s = static_cast<float>(std::min(u, 1.0));
  HandPose pose;
  // (1 - s) a + s b rather than a + s (b - a): no overflow for far-apart positions.
  pose.wrist.translation() = (1.0f - s) * a.position + s * b.position;
  pose.wrist.linear() = a.orientation.slerp(s, b.orientation).normalized().toRotationMatrix();  // shorter arc
  for (int f = 0; f < kFingerCount; ++f)
    pose.closure[f] = std::clamp((1.0f - s) * a.closure[f] + s * b.closure[f], 0.0f, 1.0f);
  return pose;
}

HandFrame HandScriptInput::frame(std::uint64_t /*step*/, double time) {
  HandFrame frame;
  frame.pose = script_.sample(time);
  frame.fingertips.fill(Vec3::Zero());  // Eigen leaves them uninitialised; a recording must be reproducible
  return frame;
}

bool HandScriptInput::finished(std::uint64_t /*step*/, double time) const { return !(time <= script_.duration()); }

}  // namespace vrd
