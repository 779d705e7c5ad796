#pragma once
// A scripted hand: keyframes of wrist pose and finger closures in time, read from a small text file
// (docs/hand-input.md), sampled by linear interpolation and slerp. For tests, demos and benchmarks
// that need the same hand motion every run without a glove.

#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "vrdeform/interact/hand_input.h"

namespace vrd {

struct HandKeyframe {
  double time = 0.0;                          ///< seconds of simulation time
  Vec3 position = Vec3::Zero();               ///< wrist position (m)
  Quat orientation = Quat::Identity();        ///< wrist orientation (unit; wrist frame in hand.h)
  std::array<float, kFingerCount> closure{};  ///< 0 open .. 1 closed, thumb to little
};

class HandScript {
 public:
  /// Checks the keyframes as parse() does (at least one; finite; times strictly increasing;
  /// closures in [0, 1]; quaternions of non-zero length, normalised here) and throws vrd::Error
  /// naming the keyframe otherwise.
  explicit HandScript(std::vector<HandKeyframe> keyframes);

  /// Reads the text format of docs/hand-input.md. Every malformed input throws vrd::Error
  /// "sourceName:line: what".
  static HandScript parse(std::string_view text, std::string_view sourceName);
  static HandScript load(const std::filesystem::path& path);

  /// The text format, with a version tag; parse(format()) gives back identical keyframes.
  std::string format() const;
  /// Writes format() to `path`, complete or not at all. Throws vrd::Error.
  void save(const std::filesystem::path& path) const;

  /// The hand at time `t` (s): position and closures linear between keyframes, orientation by slerp
  /// along the shorter arc; the first keyframe before it (and for NaN), the last after it.
  HandPose sample(double t) const;
  /// The last keyframe's time: scripts are timed from the start of the simulation.
  double duration() const { return keyframes_.back().time; }
  const std::vector<HandKeyframe>& keyframes() const { return keyframes_; }

 private:
  struct Checked {};
  HandScript(std::vector<HandKeyframe> keyframes, Checked) : keyframes_(std::move(keyframes)) {}

  std::vector<HandKeyframe> keyframes_;  // never empty
};

/// A script as a hand input source: follows the simulation clock, ignores the step number.
class HandScriptInput : public HandInput {
 public:
  explicit HandScriptInput(HandScript script) : script_(std::move(script)) {}
  HandFrame frame(std::uint64_t step, double time) override;
  /// After the last keyframe's time (and for a NaN time, so that a loop cannot run forever).
  bool finished(std::uint64_t step, double time) const override;
  const HandScript& script() const { return script_; }

 private:
  HandScript script_;
};

}  // namespace vrd
