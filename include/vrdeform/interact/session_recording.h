#pragma once
// A recorded session: the settings it ran with, and per step the hand it consumed and the values it
// produced. Saved as text with every float in hexadecimal, so a replay feeds the solver the very
// same bits and can check its outputs for equality, not closeness (format: docs/hand-input.md).

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "vrdeform/core/atomic_file.h"
#include "vrdeform/interact/hand_input.h"

namespace vrd {

struct RecordedStep {
  HandFrame frame;             ///< the hand the step consumed
  std::vector<float> outputs;  ///< what a replay checks, e.g. per-finger forces; any count per step
};

struct SessionRecording {
  /// Whatever the session needs to run again (time step, substeps, scene, ...), in order. Keys:
  /// non-empty, printable ASCII without spaces, unique. Values: printable ASCII (spaces allowed
  /// inside, not at either end), possibly empty.
  std::vector<std::pair<std::string, std::string>> settings;
  /// Step k of the session is steps[k].
  std::vector<RecordedStep> steps;

  /// The value of setting `key`; null when there is none.
  const std::string* setting(std::string_view key) const;

  /// The text format. Throws vrd::Error for a setting that could not be read back as it is.
  std::string format() const;
  /// Writes format() to `path`, complete or not at all. Throws vrd::Error.
  void save(const std::filesystem::path& path) const;
  /// Reads the text format; anything malformed (truncated, garbage, wrong counts, steps out of
  /// order) throws vrd::Error "sourceName:line: what".
  static SessionRecording parse(std::string_view text, std::string_view sourceName);
  static SessionRecording load(const std::filesystem::path& path);
};

/// Writes a recording while it is made: the settings at once and each step as it comes, so that a
/// session of any length keeps none of it in memory; finish() ends it and moves it into place,
/// complete or not at all (as SessionRecording::save, whose text it writes).
class SessionRecordingWriter {
 public:
  /// Throws vrd::Error for a setting that could not be read back, before the file is touched.
  SessionRecordingWriter(const std::filesystem::path& path,
                         const std::vector<std::pair<std::string, std::string>>& settings);
  void add(const RecordedStep& step);
  /// Throws vrd::Error when a write failed.
  void finish();
  std::uint64_t steps() const { return steps_; }

 private:
  std::string text_;  // the header first, then each step's line before it is written
  AtomicFile file_;
  std::uint64_t steps_ = 0;
};

/// Replays a recording by step number (time is ignored): step k gets steps[k].frame, bit for bit.
class RecordingInput : public HandInput {
 public:
  explicit RecordingInput(SessionRecording recording) : recording_(std::move(recording)) {}
  /// The recorded frame of `step`; past the end the last one is held (a default frame when there
  /// are no steps), as a script holds its last keyframe.
  HandFrame frame(std::uint64_t step, double time) override;
  /// True from the first step that has nothing recorded.
  bool finished(std::uint64_t step, double time) const override;
  const SessionRecording& recording() const { return recording_; }

 private:
  SessionRecording recording_;
};

}  // namespace vrd
