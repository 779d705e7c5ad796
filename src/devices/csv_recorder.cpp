#include "vrdeform/devices/csv_recorder.h"

#include "vrdeform/core/posix_fd.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <string_view>
#include <system_error>
#include <utility>

#include "vrdeform/error.h"

namespace vrd {

namespace {

constexpr std::size_t kFlushBytes = 64 * 1024;  // write early when this much is waiting
// Each present finger's columns, after its name (docs/outputs.md).
constexpr std::string_view kFingerColumns[] = {"",          "_N", "_raw", "_baseline", "_depth_m",
                                               "_contacts", "_x", "_y",   "_z"};

template <typename T>
void appendNumber(std::string& out, T value) {
  char text[40];
  const auto result = std::to_chars(text, text + sizeof text, value);  // shortest exact form, no locale
  out.append(text, result.ptr);
}

void appendMilliseconds(std::string& out, std::chrono::steady_clock::duration d) {
  char text[40];
  const double ms = std::chrono::duration<double, std::milli>(d).count();
  const auto result = std::to_chars(text, text + sizeof text, ms, std::chars_format::fixed, 3);
  out.append(text, result.ptr);
}

}  // namespace

CsvRecorder::CsvRecorder(std::filesystem::path path, const std::array<bool, kFingerCount>& present,
                         std::chrono::milliseconds flushInterval)
    : path_(std::move(path)),
      present_(present),
      flushInterval_(std::max(flushInterval, std::chrono::milliseconds(0))),
      start_(std::chrono::steady_clock::now()),
      lastFlush_(start_) {
  do {
    fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  } while (fd_ < 0 && errno == EINTR);
  if (fd_ < 0) throw Error(fmt::format("cannot write {}: {}", path_.string(), errnoText(errno)));

  header_ = "step,time_s,wall_ms,paper,paper_raw,grasp";
  for (int f = 0; f < kFingerCount; ++f)
    if (present_[f])
      for (std::string_view column : kFingerColumns) header_ += fmt::format(",{}{}", fingerName(Finger(f)), column);
  buffer_.reserve(kFlushBytes + 1024);  // rows are appended without allocating
  buffer_.append(header_);
  buffer_ += '\n';
  if (!writeBuffer()) {
    ::close(fd_);
    throw Error(error_);
  }
}

CsvRecorder::~CsvRecorder() {
  flush();
  ::close(fd_);  // everything was written by flush(); a close error has nobody left to tell
}

void CsvRecorder::send(const HapticSample& sample) {
  const auto now = std::chrono::steady_clock::now();
  const HapticSample s = sanitised(sample);
  lastTime_ = s.time;
  lastStep_ = s.step;
  anySample_ = true;
  releasedRow_ = false;
  if (failed()) {
    ++rowsDropped_;
    return;
  }
  appendRow(s, now);
  if (buffer_.size() >= kFlushBytes || now - lastFlush_ >= flushInterval_) flush();
}

void CsvRecorder::release() {
  if (anySample_ && !releasedRow_) {
    HapticSample zero;
    zero.step = lastStep_;
    zero.time = lastTime_;
    zero.present = present_;
    if (failed())
      ++rowsDropped_;
    else
      appendRow(zero, std::chrono::steady_clock::now());
    releasedRow_ = true;
  }
  flush();
}

void CsvRecorder::flush() {
  lastFlush_ = std::chrono::steady_clock::now();
  writeBuffer();
}

void CsvRecorder::appendRow(const HapticSample& s, std::chrono::steady_clock::time_point now) {
  const auto field = [&](auto value) {
    buffer_ += ',';
    appendNumber(buffer_, value);
  };
  appendNumber(buffer_, s.step);
  field(s.time);
  buffer_ += ',';
  appendMilliseconds(buffer_, now - start_);
  field(s.paper);
  field(s.paperRaw);
  buffer_ += s.grasp ? ",1" : ",0";
  for (int f = 0; f < kFingerCount; ++f) {
    if (!present_[f]) continue;
    for (const float v : {s.force[f], s.newtons[f], s.raw[f], s.baseline[f], s.depth[f]}) field(v);
    field(s.contacts[f]);
    for (int axis = 0; axis < 3; ++axis) field(s.tip[f][axis]);
  }
  buffer_ += '\n';
  ++bufferRows_;
}

bool CsvRecorder::writeBuffer() {
  if (buffer_.empty()) return true;
  const char* data = buffer_.data();
  std::size_t left = buffer_.size();
  while (left > 0 && !failed()) {
    const ssize_t n = ::write(fd_, data, left);
    if (n > 0) {
      data += n;
      left -= static_cast<std::size_t>(n);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else {
      const int code = n < 0 ? errno : ENOSPC;
      // Cut a partly written row off, so that every line in the file stays whole (a regular file;
      // for anything else this fails harmlessly).
      if (::ftruncate(fd_, static_cast<off_t>(fileBytes_)) != 0) {
      }
      error_ = fmt::format("cannot write {}: {}; it holds the first {} rows, later rows are dropped", path_.string(),
                           errnoText(code), rowsWritten_);
    }
  }
  if (left == 0) {
    fileBytes_ += buffer_.size();
    rowsWritten_ += bufferRows_;
  } else {
    rowsDropped_ += bufferRows_;
  }
  buffer_.clear();
  bufferRows_ = 0;
  return left == 0;
}

}  // namespace vrd
