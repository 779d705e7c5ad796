#pragma once
// Records the haptic signal to a CSV file, one row per sample; the one per-step schema of every
// command (`run --out`'s forces.csv, `--forces` on run and touch; docs/outputs.md):
//
//   step,time_s,wall_ms,paper,paper_raw,grasp, then per present finger F:
//   F,F_N,F_raw,F_baseline,F_depth_m,F_contacts,F_x,F_y,F_z
//
// step counts the steps done and time_s is step x dt (the simulation time); wall_ms the
// steady-clock time since the recorder was made; paper and paper_raw Algorithm 2's value for the
// hand and its F_raw; grasp 1 while a grasp holds the body. Per finger: the normalised force the
// glove gets, the force in newtons, F_raw, the condition B baseline, the indentation in metres,
// the contacts that pushed and the fingertip centre (m). Numbers are written with std::to_chars
// (shortest form that reads back exactly, '.' whatever the locale); wall_ms with three decimals.
//
// Streaming, not all-or-nothing: rows are collected in memory and written to the file itself,
// whole rows at a time, at least every `flushInterval`, on flush(), release() and destruction. A
// crash loses at most the rows since the last flush and leaves a CSV whose every line is
// complete. Writing does not fsync: a power cut may lose what the OS had not written yet.

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>

#include "vrdeform/devices/haptic_output.h"

namespace vrd {

class CsvRecorder final : public HapticOutput {
 public:
  /// Creates (or truncates) `path` and writes the header, with columns for the `present` fingers.
  /// Throws vrd::Error when the file cannot be created or the header cannot be written.
  CsvRecorder(std::filesystem::path path, const std::array<bool, kFingerCount>& present,
              std::chrono::milliseconds flushInterval = std::chrono::milliseconds(500));
  /// Flushes and closes the file (no release row).
  ~CsvRecorder() override;
  CsvRecorder(const CsvRecorder&) = delete;
  CsvRecorder& operator=(const CsvRecorder&) = delete;

  /// Appends one row (values sanitised; the sample's absent fingers read as 0). Never throws: after a
  /// write failure rows are dropped and counted, and error() says why.
  void send(const HapticSample& sample) override;
  /// Appends a row of zeros at the last sample's time (marking where the device was released; not
  /// repeated, and none before the first sample) and flushes.
  void release() override;
  /// Writes the collected rows to the file now.
  void flush();

  /// True once a write has failed; the file then holds the rows before the failure, every line whole.
  bool failed() const { return !error_.empty(); }
  /// The first write failure ("" while there is none); later failures do not overwrite it.
  const std::string& error() const { return error_; }
  std::size_t rowsWritten() const { return rowsWritten_; }  ///< rows in the file (after the header)
  std::size_t rowsDropped() const { return rowsDropped_; }  ///< rows lost to a write failure
  const std::filesystem::path& path() const { return path_; }
  const std::string& header() const { return header_; }  ///< the header line, without its newline

 private:
  void appendRow(const HapticSample& sample, std::chrono::steady_clock::time_point now);
  bool writeBuffer();

  std::filesystem::path path_;
  std::array<bool, kFingerCount> present_;
  std::chrono::steady_clock::duration flushInterval_;
  std::chrono::steady_clock::time_point start_, lastFlush_;
  int fd_ = -1;
  std::string header_;
  std::string buffer_;          // whole rows not yet written
  std::size_t bufferRows_ = 0;  // rows in buffer_
  std::size_t fileBytes_ = 0;   // bytes of whole lines in the file
  std::size_t rowsWritten_ = 0, rowsDropped_ = 0;
  double lastTime_ = 0.0;
  std::uint64_t lastStep_ = 0;
  bool anySample_ = false, releasedRow_ = false;
  std::string error_;
};

}  // namespace vrd
