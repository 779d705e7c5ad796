// Outputs of the haptic signal besides the glove: the CSV recorder and OSC over UDP (received here
// with a liblo server in the test).

#include <gtest/gtest.h>
#include <lo/lo.h>
#include <netinet/in.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <charconv>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "test_support.h"
#include "vrdeform/devices/csv_recorder.h"
#include "vrdeform/devices/haptic_output.h"
#include "vrdeform/devices/osc_output.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;
using std::chrono::milliseconds;
using testing::errorOf;

constexpr std::array<bool, kFingerCount> kG1{true, true, true, false, false};
constexpr std::array<bool, kFingerCount> kPro{true, true, true, true, true};
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

// Every field set, each finger's values different: a column in the wrong place shows.
HapticSample makeSample(double time, const std::array<bool, kFingerCount>& present, float scale = 1.0f) {
  HapticSample s;
  s.step = std::uint64_t(std::llround(time * 60.0));
  s.time = time;
  s.present = present;
  s.paper = 0.5f * scale;
  s.paperRaw = 0.625f * scale;
  s.grasp = scale == 1.0f;
  for (int f = 0; f < kFingerCount; ++f) {
    s.force[f] = 0.1f * float(f + 1) * scale;
    s.newtons[f] = 1.5f * float(f + 1) * scale;
    s.raw[f] = 0.125f * float(f + 1) * scale;
    s.baseline[f] = 0.0625f * float(f + 1) * scale;
    s.depth[f] = 1e-3f * float(f + 1) * scale;
    s.contacts[f] = std::uint32_t(f + 2);
    s.tip[f] = Vec3(0.01f * float(f), -0.02f, 0.25f * scale);
  }
  return s;
}

// The header `run --out` and `--forces` write for `fingers` (docs/outputs.md).
std::string csvHeader(const std::vector<std::string>& fingers) {
  std::string h = "step,time_s,wall_ms,paper,paper_raw,grasp";
  for (const std::string& f : fingers)
    for (const char* c : {"", "_N", "_raw", "_baseline", "_depth_m", "_contacts", "_x", "_y", "_z"}) h += "," + f + c;
  return h;
}

// --- files -------------------------------------------------------------------------------------

using testing::TempDir;

using testing::readBytes;

std::vector<std::string> splitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  for (std::size_t end; (end = text.find('\n', start)) != std::string::npos; start = end + 1)
    lines.push_back(text.substr(start, end - start));
  EXPECT_EQ(start, text.size()) << "the file ends inside a line";
  return lines;
}

std::vector<std::string> splitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  for (std::size_t end; (end = line.find(',', start)) != std::string::npos; start = end + 1)
    fields.push_back(line.substr(start, end - start));
  fields.push_back(line.substr(start));
  return fields;
}

double number(const std::string& field) {
  double value = std::numeric_limits<double>::quiet_NaN();
  const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
  EXPECT_TRUE(ec == std::errc() && end == field.data() + field.size()) << "not a number: \"" << field << "\"";
  return value;
}

// --- the sample ----------------------------------------------------------------------------------

TEST(HapticOutputs, SampleOfTakesPresentFingersAndSanitises) {
  HapticFrame frame;
  frame.paper = kNaN;
  frame.paperRaw = 0.75f;
  frame.fingers[0] = {0.25f, 0.3f, 2.0f, 0.1f, 3, 0.004f};
  frame.fingers[1] = {1.5f, 0.0f, kInf, 0.0f, 1, kNaN};
  frame.fingers[2] = {-0.5f, 0.0f, -3.0f, 0.0f, 0, -1.0f};
  frame.fingers[3] = {0.75f, 0.0f, 4.0f, 0.0f, 2, 0.5f};  // absent on a G1 hand
  const HapticSample s = sampleOf(75, 1.0 / 60.0, frame, kG1);
  EXPECT_EQ(s.step, 75u);
  EXPECT_EQ(s.time, 75 * (1.0 / 60.0));  // step x dt, not a sum of dt
  EXPECT_EQ(s.paper, 0.0f);
  EXPECT_EQ(s.paperRaw, 0.75f);
  EXPECT_EQ(s.present, kG1);
  EXPECT_EQ(s.force, (std::array<float, kFingerCount>{0.25f, 1.0f, 0.0f, 0.0f, 0.0f}));
  EXPECT_EQ(s.newtons, (std::array<float, kFingerCount>{2.0f, 0.0f, 0.0f, 0.0f, 0.0f}));
  EXPECT_EQ(s.raw, (std::array<float, kFingerCount>{0.3f, 0.0f, 0.0f, 0.0f, 0.0f}));
  EXPECT_EQ(s.baseline, (std::array<float, kFingerCount>{0.1f, 0.0f, 0.0f, 0.0f, 0.0f}));
  EXPECT_EQ(s.depth, (std::array<float, kFingerCount>{0.004f, 0.0f, 0.0f, 0.0f, 0.0f}));
  EXPECT_EQ(s.contacts, (std::array<std::uint32_t, kFingerCount>{3, 1, 0, 0, 0}));

  HapticSample bad = makeSample(std::numeric_limits<double>::infinity(), kPro);
  bad.force[4] = -kInf;
  bad.newtons[4] = kNaN;
  bad.tip[4] = Vec3(kNaN, 1.0f, kInf);
  const HapticSample clean = sanitised(bad);
  EXPECT_EQ(clean.time, 0.0);
  EXPECT_EQ(clean.force[4], 0.0f);
  EXPECT_EQ(clean.newtons[4], 0.0f);
  EXPECT_EQ(clean.tip[4], Vec3(0.0f, 1.0f, 0.0f));
  EXPECT_EQ(clean.force[1], bad.force[1]);
  EXPECT_EQ(clean.tip[1], bad.tip[1]);
  EXPECT_EQ(fingerName(Finger::Little), "little");
}

// --- CSV recorder --------------------------------------------------------------------------------

// A study's condition B: the glove gets the baseline where the force was, everything else as it came.
TEST(HapticOutputs, BaselineAsForcePassesTheBaselineInTheForcesPlace) {
  struct Last final : HapticOutput {
    HapticSample sample;
    int releases = 0;
    void send(const HapticSample& s) override { sample = s; }
    void release() override { ++releases; }
  } glove;
  BaselineAsForce b(glove);
  const HapticSample s = makeSample(0.5, kG1);
  b.send(s);
  for (int f = 0; f < kFingerCount; ++f) {
    EXPECT_EQ(glove.sample.force[f], s.baseline[f]) << f;
    EXPECT_EQ(glove.sample.baseline[f], s.baseline[f]) << f;
    EXPECT_EQ(glove.sample.newtons[f], s.newtons[f]) << f;
  }
  EXPECT_EQ(glove.sample.step, s.step);
  b.release();
  EXPECT_EQ(glove.releases, 1);
}

TEST(CsvRecorder, HeaderAndRowsForG1Hand) {
  TempDir dir;
  const fs::path path = dir / "g1.csv";
  const std::string header = csvHeader({"thumb", "index", "middle"});
  {
    CsvRecorder recorder(path, kG1);
    EXPECT_EQ(recorder.header(), header);
    recorder.send(makeSample(0.0, kG1));
    recorder.send(makeSample(1.0 / 60.0, kG1, 0.5f));
    EXPECT_FALSE(recorder.failed());
  }
  const auto lines = splitLines(readBytes(path));
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], header);
  for (int row = 0; row < 2; ++row) {
    const auto fields = splitFields(lines[1 + row]);
    ASSERT_EQ(fields.size(), 6u + 3u * 9u) << lines[1 + row];
    const HapticSample expected = makeSample(row == 0 ? 0.0 : 1.0 / 60.0, kG1, row == 0 ? 1.0f : 0.5f);
    EXPECT_EQ(number(fields[0]), double(expected.step));
    EXPECT_EQ(number(fields[1]), expected.time);  // shortest form reads back exactly
    EXPECT_GE(number(fields[2]), 0.0);            // wall_ms
    EXPECT_EQ(float(number(fields[3])), expected.paper);
    EXPECT_EQ(float(number(fields[4])), expected.paperRaw);
    EXPECT_EQ(fields[5], expected.grasp ? "1" : "0");
    for (int f = 0; f < 3; ++f) {
      const std::size_t at = 6 + 9 * std::size_t(f);
      EXPECT_EQ(float(number(fields[at])), expected.force[f]);
      EXPECT_EQ(float(number(fields[at + 1])), expected.newtons[f]);
      EXPECT_EQ(float(number(fields[at + 2])), expected.raw[f]);
      EXPECT_EQ(float(number(fields[at + 3])), expected.baseline[f]);
      EXPECT_EQ(float(number(fields[at + 4])), expected.depth[f]);
      EXPECT_EQ(number(fields[at + 5]), double(expected.contacts[f]));
      for (int axis = 0; axis < 3; ++axis) EXPECT_EQ(float(number(fields[at + 6 + axis])), expected.tip[f][axis]);
    }
  }
  EXPECT_LE(number(splitFields(lines[1])[2]), number(splitFields(lines[2])[2]));  // wall clock goes forward
}

TEST(CsvRecorder, HeaderAndRowsForProHand) {
  TempDir dir;
  const fs::path path = dir / "pro.csv";
  {
    CsvRecorder recorder(path, kPro);
    recorder.send(makeSample(2.5, kPro));
  }
  const auto lines = splitLines(readBytes(path));
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0], csvHeader({"thumb", "index", "middle", "ring", "little"}));
  const auto fields = splitFields(lines[1]);
  ASSERT_EQ(fields.size(), 6u + 5u * 9u);
  EXPECT_EQ(fields[0], "150");
  EXPECT_EQ(fields[1], "2.5");
  EXPECT_EQ(fields[3], "0.5");
  EXPECT_EQ(float(number(fields[6 + 4 * 9])), 0.5f);      // little: 0.1 * 5
  EXPECT_EQ(float(number(fields[6 + 4 * 9 + 1])), 7.5f);  // little_N: 1.5 * 5
  EXPECT_EQ(fields[6 + 4 * 9 + 5], "6");                  // little_contacts
}

TEST(CsvRecorder, WritesNaNAndOutOfRangeValuesClamped) {
  TempDir dir;
  const fs::path path = dir / "clamped.csv";
  {
    CsvRecorder recorder(path, kG1);
    HapticSample s = makeSample(0.5, kG1);
    s.paper = 3.0f;
    s.force = {kNaN, -0.25f, 7.0f, 0.0f, 0.0f};
    s.newtons = {kInf, kNaN, -2.0f, 0.0f, 0.0f};
    s.depth[0] = kNaN;
    s.tip[2] = Vec3(kInf, kNaN, 0.5f);
    recorder.send(s);
  }
  const auto lines = splitLines(readBytes(path));
  ASSERT_EQ(lines.size(), 2u);
  const auto fields = splitFields(lines[1]);
  ASSERT_EQ(fields.size(), 6u + 3u * 9u);
  EXPECT_EQ(fields[3], "1");           // paper 3 -> 1
  EXPECT_EQ(fields[6], "0");           // thumb NaN -> 0
  EXPECT_EQ(fields[7], "0");           // thumb inf N -> 0
  EXPECT_EQ(fields[10], "0");          // thumb NaN depth -> 0
  EXPECT_EQ(fields[6 + 9], "0");       // index -0.25 -> 0
  EXPECT_EQ(fields[6 + 9 + 1], "0");   // index NaN N -> 0
  EXPECT_EQ(fields[6 + 18], "1");      // middle 7 -> 1
  EXPECT_EQ(fields[6 + 18 + 1], "0");  // middle negative N -> 0
  EXPECT_EQ(fields[6 + 18 + 6], "0");  // middle x inf -> 0
  EXPECT_EQ(fields[6 + 18 + 8], "0.5");
  EXPECT_EQ(lines[1].find("nan"), std::string::npos) << lines[1];
  EXPECT_EQ(lines[1].find("inf"), std::string::npos) << lines[1];
}

TEST(CsvRecorder, UnwritablePathIsAnError) {
  TempDir dir;
  EXPECT_NE(errorOf([&] { CsvRecorder(dir / "no_such_dir" / "x.csv", kG1); }).find("no_such_dir"), std::string::npos);
  EXPECT_NE(errorOf([&] { CsvRecorder(dir / "", kG1); }).find("cannot write"), std::string::npos);  // a directory
  if (fs::exists("/dev/full")) {  // opens, but every write fails with "no space left"
    EXPECT_NE(errorOf([&] { CsvRecorder("/dev/full", kG1); }).find("/dev/full"), std::string::npos);
  }
}

TEST(CsvRecorder, FileIsCompleteAfterDestruction) {
  TempDir dir;
  const fs::path path = dir / "long.csv";
  constexpr int kRows = 20000;  // more than one flush buffer, within one flush interval
  {
    CsvRecorder recorder(path, kPro, std::chrono::hours(1));
    for (int i = 0; i < kRows; ++i) recorder.send(makeSample(i * 0.001, kPro, float(i % 7) / 7.0f));
    EXPECT_GT(fs::file_size(path), 0u);  // whole buffers already went out
  }
  const auto lines = splitLines(readBytes(path));
  ASSERT_EQ(lines.size(), std::size_t(kRows) + 1);
  for (std::size_t i = 1; i < lines.size(); ++i) ASSERT_EQ(splitFields(lines[i]).size(), 51u) << "line " << i;
  EXPECT_EQ(number(splitFields(lines.back())[1]), (kRows - 1) * 0.001);
}

TEST(CsvRecorder, FlushesPeriodicallyAndOnRelease) {
  TempDir dir;
  const fs::path path = dir / "flush.csv";
  CsvRecorder every(path, kG1, milliseconds(0));
  every.send(makeSample(0.0, kG1));
  EXPECT_EQ(splitLines(readBytes(path)).size(), 2u);  // in the file while the recorder lives

  const fs::path held = dir / "held.csv";
  CsvRecorder hourly(held, kG1, std::chrono::hours(1));
  hourly.release();  // nothing sent yet: no release row
  hourly.send(makeSample(0.25, kG1));
  EXPECT_EQ(splitLines(readBytes(held)).size(), 1u);  // header only, the row waits
  hourly.release();
  hourly.release();  // one release row, not two
  const auto lines = splitLines(readBytes(held));
  ASSERT_EQ(lines.size(), 3u);
  const auto zero = splitFields(lines[2]);
  EXPECT_EQ(zero[0], "15");    // at the last sample's step
  EXPECT_EQ(zero[1], "0.25");  // and time
  for (std::size_t i = 3; i < zero.size(); ++i) EXPECT_EQ(zero[i], "0") << i;
  EXPECT_EQ(hourly.rowsWritten(), 2u);
}

// RLIMIT_FSIZE makes writes past a size fail (EFBIG) like a full disk, for this process only.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &old_);
    oldHandler_ = std::signal(SIGXFSZ, SIG_IGN);  // fail the write instead of killing the process
    rlimit limit = old_;
    limit.rlim_cur = bytes;
    ok_ = ::setrlimit(RLIMIT_FSIZE, &limit) == 0;
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, oldHandler_);
  }
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;
  bool ok() const { return ok_; }

 private:
  rlimit old_{};
  void (*oldHandler_)(int) = SIG_DFL;
  bool ok_ = false;
};

TEST(CsvRecorder, DiskFullDuringRunIsReportedNotThrown) {
  TempDir dir;
  const fs::path path = dir / "full.csv";
  constexpr int kRows = 200;
  std::size_t written = 0, dropped = 0;
  std::string error;
  {
    CsvRecorder recorder(path, kPro, milliseconds(0));  // write every row at once
    {
      const FileSizeLimit limit(2000);
      if (!limit.ok()) GTEST_SKIP() << "cannot lower RLIMIT_FSIZE";
      for (int i = 0; i < kRows; ++i) EXPECT_NO_THROW(recorder.send(makeSample(i * 0.01, kPro)));
      EXPECT_NO_THROW(recorder.release());
    }
    EXPECT_TRUE(recorder.failed());
    error = recorder.error();
    written = recorder.rowsWritten();
    dropped = recorder.rowsDropped();
    recorder.send(makeSample(9.0, kPro));  // the limit is gone, but the recorder stays stopped
    EXPECT_EQ(recorder.error(), error);    // reported once: the first failure
    EXPECT_EQ(recorder.rowsWritten(), written);
    EXPECT_EQ(recorder.rowsDropped(), dropped + 1);
  }
  RecordProperty("error", error);
  EXPECT_NE(error.find("full.csv"), std::string::npos) << error;
  EXPECT_GT(written, 0u);
  EXPECT_LT(written, std::size_t(kRows));
  EXPECT_EQ(written + dropped, std::size_t(kRows) + 1);  // + the release row
  const std::string text = readBytes(path);
  EXPECT_LE(text.size(), 2000u);
  const auto lines = splitLines(text);  // every line whole: the partial row was cut off
  ASSERT_EQ(lines.size(), written + 1);
  for (std::size_t i = 1; i < lines.size(); ++i) EXPECT_EQ(splitFields(lines[i]).size(), 51u) << lines[i];
}

// --- OSC -----------------------------------------------------------------------------------------

struct OscMessage {
  std::string path, types;
  std::vector<double> values;
};

/// A liblo server on a free UDP port, polled from the test thread.
class OscReceiver {
 public:
  OscReceiver() {
    server_ = lo_server_new_with_proto(nullptr, LO_UDP, [](int, const char*, const char*) {});
    if (!server_) return;
    lo_server_add_method(server_, nullptr, nullptr, &OscReceiver::handle, this);
    port_ = lo_server_get_port(server_);
  }
  ~OscReceiver() {
    if (server_) lo_server_free(server_);
  }
  OscReceiver(const OscReceiver&) = delete;
  OscReceiver& operator=(const OscReceiver&) = delete;

  int port() const { return port_; }
  /// Receives until `count` messages are in (or `timeout` passes) and takes them.
  std::vector<OscMessage> take(std::size_t count, milliseconds timeout = milliseconds(2000)) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (messages_.size() < count && std::chrono::steady_clock::now() < end) lo_server_recv_noblock(server_, 10);
    std::vector<OscMessage> out;
    out.swap(messages_);
    return out;
  }

 private:
  static int handle(const char* path, const char* types, lo_arg** argv, int argc, lo_message, void* self) {
    OscMessage m{path, types, {}};
    for (int i = 0; i < argc; ++i) {  // liblo's arguments are only 4-byte aligned: copy them out
      if (types[i] == LO_FLOAT) {
        float f;
        std::memcpy(&f, argv[i], sizeof f);
        m.values.push_back(f);
      } else if (types[i] == LO_DOUBLE) {
        double d;
        std::memcpy(&d, argv[i], sizeof d);
        m.values.push_back(d);
      }
    }
    static_cast<OscReceiver*>(self)->messages_.push_back(std::move(m));
    return 0;
  }

  lo_server server_ = nullptr;
  int port_ = 0;
  std::vector<OscMessage> messages_;
};

/// Checks the four messages of one sample, in their order.
void expectSample(const std::vector<OscMessage>& got, std::size_t first, const std::string& prefix,
                  const HapticSample& expected) {
  ASSERT_GE(got.size(), first + 4);
  EXPECT_EQ(got[first].path, prefix + "/time");
  EXPECT_EQ(got[first].types, "d");
  ASSERT_EQ(got[first].values.size(), 1u);
  EXPECT_EQ(got[first].values[0], expected.time);
  EXPECT_EQ(got[first + 1].path, prefix + "/paper");
  EXPECT_EQ(got[first + 1].types, "f");
  ASSERT_EQ(got[first + 1].values.size(), 1u);
  EXPECT_FLOAT_EQ(float(got[first + 1].values[0]), expected.paper);
  EXPECT_EQ(got[first + 2].path, prefix + "/force");
  EXPECT_EQ(got[first + 2].types, "fffff");
  EXPECT_EQ(got[first + 3].path, prefix + "/newtons");
  EXPECT_EQ(got[first + 3].types, "fffff");
  ASSERT_EQ(got[first + 2].values.size(), 5u);
  ASSERT_EQ(got[first + 3].values.size(), 5u);
  for (int f = 0; f < kFingerCount; ++f) {
    EXPECT_FLOAT_EQ(float(got[first + 2].values[f]), expected.present[f] ? expected.force[f] : 0.0f) << f;
    EXPECT_FLOAT_EQ(float(got[first + 3].values[f]), expected.present[f] ? expected.newtons[f] : 0.0f) << f;
  }
}

HapticSample zerosAt(double time) {
  HapticSample zero;
  zero.time = time;
  return zero;
}

TEST(OscOutput, SendsOneBundlePerSample) {
  OscReceiver receiver;
  ASSERT_GT(receiver.port(), 0);
  OscOutput out("127.0.0.1", receiver.port());
  EXPECT_EQ(out.destination(), "127.0.0.1:" + std::to_string(receiver.port()));
  const HapticSample a = makeSample(0.5, kG1), b = makeSample(0.75, kG1, 0.5f);
  out.send(a);
  out.send(b);
  const auto got = receiver.take(8);
  ASSERT_EQ(got.size(), 8u);
  expectSample(got, 0, "/vrdeform", a);  // ring and little absent: 0
  expectSample(got, 4, "/vrdeform", b);
  EXPECT_EQ(out.samplesSent(), 2u);
  EXPECT_EQ(out.errors(), 0u);
  EXPECT_EQ(out.firstError(), "");
}

TEST(OscOutput, PlainMessagesWithOwnPrefix) {
  OscReceiver receiver;
  OscOutput out("127.0.0.1", receiver.port(), "/lab/glove2", OscOptions{0.0, false});
  const HapticSample s = makeSample(3.0, kPro);
  out.send(s);
  const auto got = receiver.take(4);
  ASSERT_EQ(got.size(), 4u);
  expectSample(got, 0, "/lab/glove2", s);
}

TEST(OscOutput, SendsClampedValues) {
  OscReceiver receiver;
  OscOutput out("127.0.0.1", receiver.port());
  HapticSample s = makeSample(1.0, kPro);
  s.paper = kNaN;
  s.force = {kNaN, 2.0f, -1.0f, kInf, 0.5f};
  s.newtons = {kInf, kNaN, -4.0f, 3.0f, 0.0f};
  out.send(s);
  const auto got = receiver.take(4);
  ASSERT_EQ(got.size(), 4u);
  EXPECT_EQ(got[1].values, std::vector<double>{0.0});
  EXPECT_EQ(got[2].values, (std::vector<double>{0.0, 1.0, 0.0, 1.0, 0.5}));
  EXPECT_EQ(got[3].values, (std::vector<double>{0.0, 0.0, 0.0, 3.0, 0.0}));
}

TEST(OscOutput, ReleaseSendsZeros) {
  OscReceiver receiver;
  {
    OscOutput out("127.0.0.1", receiver.port());
    out.send(makeSample(2.0, kPro));
    out.release();
    const auto got = receiver.take(8);
    ASSERT_EQ(got.size(), 8u);
    expectSample(got, 4, "/vrdeform", zerosAt(2.0));  // zeros at the last sample's time
  }
  EXPECT_TRUE(receiver.take(1, milliseconds(100)).empty());  // released already: no second release

  {
    OscOutput out("127.0.0.1", receiver.port());
    out.send(makeSample(4.0, kG1));
  }  // destroyed while pressing: releases
  const auto got = receiver.take(8);
  ASSERT_EQ(got.size(), 8u);
  expectSample(got, 4, "/vrdeform", zerosAt(4.0));
}

TEST(OscOutput, RateLimitSendsNewestAndNothingStaleAfterRelease) {
  OscReceiver receiver;
  OscOutput out("127.0.0.1", receiver.port(), "/vrdeform", OscOptions{5.0, true});  // one per 200 ms
  out.send(makeSample(0.0, kPro));
  out.send(makeSample(0.1, kPro, 0.9f));  // held back ...
  out.send(makeSample(0.2, kPro, 0.8f));  // ... replaced by the newer one
  auto got = receiver.take(8, milliseconds(100));
  ASSERT_EQ(got.size(), 4u);
  expectSample(got, 0, "/vrdeform", makeSample(0.0, kPro));
  out.flush();  // the newest held-back sample goes now
  got = receiver.take(4);
  ASSERT_EQ(got.size(), 4u);
  expectSample(got, 0, "/vrdeform", makeSample(0.2, kPro, 0.8f));
  out.flush();  // nothing held back any more
  EXPECT_TRUE(receiver.take(1, milliseconds(50)).empty());

  out.send(makeSample(0.3, kPro, 0.7f));  // held back (within 200 ms of the flush) ...
  out.release();                          // ... and dropped by the release
  out.flush();
  got = receiver.take(8, milliseconds(100));
  ASSERT_EQ(got.size(), 4u);
  expectSample(got, 0, "/vrdeform", zerosAt(0.3));

  std::this_thread::sleep_for(milliseconds(250));
  out.send(makeSample(0.4, kPro, 0.6f));  // the interval has passed: goes at once
  got = receiver.take(4);
  ASSERT_EQ(got.size(), 4u);
  expectSample(got, 0, "/vrdeform", makeSample(0.4, kPro, 0.6f));
  EXPECT_EQ(out.errors(), 0u);
}

TEST(OscOutput, BadDestinationIsAnError) {
  EXPECT_NE(errorOf([] { OscOutput("", 9000); }).find("host"), std::string::npos);
  EXPECT_NE(errorOf([] { OscOutput("not a host!", 9000); }).find("not a host!"), std::string::npos);
  EXPECT_NE(errorOf([] { OscOutput("127.0.0.1", 0); }).find("port 0"), std::string::npos);
  EXPECT_NE(errorOf([] { OscOutput("127.0.0.1", 65536); }).find("65536"), std::string::npos);
  EXPECT_NE(errorOf([] { OscOutput("127.0.0.1", 9000, "vrdeform"); }).find("prefix"), std::string::npos);
  EXPECT_NE(errorOf([] { OscOutput("127.0.0.1", 9000, "/a b"); }).find("prefix"), std::string::npos);
  EXPECT_NE(errorOf([] { OscOutput("127.0.0.1", 9000, "/a/"); }).find("prefix"), std::string::npos);
  EXPECT_NE(errorOf([] { OscOutput("127.0.0.1", 9000, "/a*"); }).find("prefix"), std::string::npos);
  EXPECT_NE(errorOf([] { OscOutput("127.0.0.1", 9000, "/v", OscOptions{-1.0}); }).find("maxRateHz"), std::string::npos);
  EXPECT_NE(errorOf([] { OscOutput("127.0.0.1", 9000, "/v", OscOptions{std::nan("")}); }).find("maxRateHz"),
            std::string::npos);
  EXPECT_NO_THROW(OscOutput("localhost", 9000, ""));  // from /etc/hosts, no DNS
}

TEST(OscOutput, ParseHostPort) {
  const HostPort a = parseHostPort("localhost:9000");
  EXPECT_EQ(a.host, "localhost");
  EXPECT_EQ(a.port, 9000);
  const HostPort b = parseHostPort("[::1]:57120");
  EXPECT_EQ(b.host, "::1");
  EXPECT_EQ(b.port, 57120);
  EXPECT_EQ(parseHostPort("192.168.1.20:8000").host, "192.168.1.20");
  for (const char* bad : {"localhost", "localhost:", ":9000", "host:abc", "host:0", "host:70000", "host:90x",
                          "::1:9000", "[::1]9000", "[::1]", ""})
    EXPECT_FALSE(errorOf([&] { parseHostPort(bad); }).empty()) << bad;
}

TEST(OscOutput, NobodyListeningDoesNotThrowOrBlock) {
  // A port that was free a moment ago: bind one, note it, close it.
  const int probe = ::socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(probe, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  ASSERT_EQ(::bind(probe, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  ASSERT_EQ(::getsockname(probe, reinterpret_cast<sockaddr*>(&address), &length), 0);
  ::close(probe);

  OscOutput out("127.0.0.1", ntohs(address.sin_port));
  constexpr int kSamples = 2000;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < kSamples; ++i) EXPECT_NO_THROW(out.send(makeSample(i * 0.001, kPro)));
  EXPECT_NO_THROW(out.release());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 2.0);  // microseconds each; a blocked send would take far longer
  EXPECT_EQ(out.samplesSent() + out.errors(), std::size_t(kSamples) + 1);
  testing::record("osc_send_us", 1e6 * seconds / (kSamples + 1));
}

// --- both, through the interface -----------------------------------------------------------------

TEST(HapticOutputs, OneSignalToSeveralOutputs) {
  TempDir dir;
  OscReceiver receiver;
  std::vector<std::unique_ptr<HapticOutput>> outputs;
  outputs.push_back(std::make_unique<CsvRecorder>(dir / "both.csv", kG1));
  outputs.push_back(std::make_unique<OscOutput>("127.0.0.1", receiver.port()));
  HapticFrame frame;
  frame.paper = 0.4f;
  frame.fingers[1].force = 0.6f;
  frame.fingers[1].newtons = 1.2f;
  const HapticSample sample = sampleOf(6, 1.0 / 60.0, frame, kG1);
  for (auto& out : outputs) out->send(sample);
  for (auto& out : outputs) out->release();
  outputs.clear();
  const auto lines = splitLines(readBytes(dir / "both.csv"));
  ASSERT_EQ(lines.size(), 3u);                     // header, the sample, the release
  EXPECT_EQ(splitFields(lines[1])[6 + 9], "0.6");  // index
  const auto got = receiver.take(8);
  ASSERT_EQ(got.size(), 8u);
  expectSample(got, 0, "/vrdeform", sample);
  expectSample(got, 4, "/vrdeform", zerosAt(sample.time));
}

}  // namespace
}  // namespace vrd
