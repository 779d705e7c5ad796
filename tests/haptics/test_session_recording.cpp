// Recorded sessions: saved and loaded bit for bit, replayed in order, and every damaged file
// rejected with its line instead of replaying something else.
#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.h"
#include "vrdeform/interact/session_recording.h"

namespace vrd {
namespace {

using testing::errorOf;
using Limits = std::numeric_limits<float>;

std::uint32_t bits(float v) { return std::bit_cast<std::uint32_t>(v); }

// Finite floats of every kind: zeros of both signs, subnormals, the extremes, and random bit patterns.
float randomFloat(std::mt19937& rng) {
  static const float special[] = {0.0f,
                                  -0.0f,
                                  Limits::denorm_min(),
                                  -Limits::denorm_min(),
                                  Limits::min(),
                                  -Limits::min(),
                                  Limits::max(),
                                  -Limits::max(),
                                  1.0f,
                                  0.1f,
                                  std::nextafter(Limits::min(), 0.0f)};
  switch (rng() % 4) {
    case 0:
      return special[rng() % std::size(special)];
    case 1:
      return std::bit_cast<float>(static_cast<std::uint32_t>(rng() & 0x807fffffu));  // subnormal or zero
    default: {
      float v;
      do v = std::bit_cast<float>(static_cast<std::uint32_t>(rng()));
      while (std::isnan(v));
      return v;
    }
  }
}

RecordedStep randomStep(std::mt19937& rng) {
  RecordedStep step;
  step.frame.direct = rng() % 2 == 1;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) step.frame.pose.wrist.matrix()(r, c) = randomFloat(rng);
  for (float& c : step.frame.pose.closure) c = randomFloat(rng);
  for (Vec3& tip : step.frame.fingertips)
    for (int a = 0; a < 3; ++a) tip[a] = randomFloat(rng);
  step.outputs.resize(rng() % 8);  // the count may change from step to step
  for (float& v : step.outputs) v = randomFloat(rng);
  return step;
}

// Every float of a and b, as bits; the first difference or "".
std::string difference(const HandFrame& a, const HandFrame& b) {
  if (a.direct != b.direct) return "direct";
  for (int i = 0; i < 16; ++i)
    if (bits(a.pose.wrist.matrix().data()[i]) != bits(b.pose.wrist.matrix().data()[i]))
      return "wrist " + std::to_string(i);
  for (int f = 0; f < kFingerCount; ++f) {
    if (bits(a.pose.closure[f]) != bits(b.pose.closure[f])) return "closure " + std::to_string(f);
    for (int k = 0; k < 3; ++k)
      if (bits(a.fingertips[f][k]) != bits(b.fingertips[f][k])) return "fingertip " + std::to_string(f);
  }
  return {};
}

void expectIdentical(const SessionRecording& a, const SessionRecording& b) {
  EXPECT_EQ(a.settings, b.settings);
  ASSERT_EQ(a.steps.size(), b.steps.size());
  for (std::size_t k = 0; k < a.steps.size(); ++k) {
    EXPECT_EQ(difference(a.steps[k].frame, b.steps[k].frame), "") << "step " << k;
    ASSERT_EQ(a.steps[k].outputs.size(), b.steps[k].outputs.size()) << "step " << k;
    for (std::size_t i = 0; i < a.steps[k].outputs.size(); ++i)
      EXPECT_EQ(bits(a.steps[k].outputs[i]), bits(b.steps[k].outputs[i])) << "step " << k << " output " << i;
  }
}

SessionRecording randomRecording(std::mt19937& rng, std::size_t steps) {
  SessionRecording r;
  r.settings = {{"scene", "poke liver #2"}, {"timeStep", "0x1.0624dep-10"}, {"substeps", "4"}, {"note", ""}};
  for (std::size_t k = 0; k < steps; ++k) r.steps.push_back(randomStep(rng));
  return r;
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::string join(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& line : lines) out += line + '\n';
  return out;
}

TEST(SessionRecording, SaveAndLoadAreBitExact) {
  std::mt19937 rng(17);
  const SessionRecording recording = randomRecording(rng, 300);
  const std::filesystem::path path = testing::scratchPath("bits.session");
  recording.save(path);
  const SessionRecording loaded = SessionRecording::load(path);
  std::filesystem::remove(path);
  expectIdentical(recording, loaded);
  EXPECT_EQ(loaded.format(), recording.format());
}

TEST(SessionRecording, InfinitiesRoundTripAndNaNKeepsItsSign) {
  SessionRecording r;
  r.steps.emplace_back();
  r.steps[0].frame.fingertips.fill(Vec3::Zero());
  r.steps[0].frame.pose.closure = {Limits::infinity(), -Limits::infinity(), Limits::quiet_NaN(), -Limits::quiet_NaN(),
                                   -0.0f};
  r.steps[0].outputs = {-Limits::quiet_NaN(), Limits::infinity()};
  const SessionRecording back = SessionRecording::parse(r.format(), "nan");
  const auto& c = back.steps[0].frame.pose.closure;
  EXPECT_EQ(bits(c[0]), bits(Limits::infinity()));
  EXPECT_EQ(bits(c[1]), bits(-Limits::infinity()));
  EXPECT_TRUE(std::isnan(c[2]) && !std::signbit(c[2]));
  EXPECT_TRUE(std::isnan(c[3]) && std::signbit(c[3]));
  EXPECT_EQ(bits(c[4]), bits(-0.0f));
  EXPECT_TRUE(std::isnan(back.steps[0].outputs[0]) && std::signbit(back.steps[0].outputs[0]));
  EXPECT_EQ(back.steps[0].outputs[1], Limits::infinity());
}

TEST(SessionRecording, FloatsAreCHexfloats) {
  SessionRecording r;
  r.steps.emplace_back();
  r.steps[0].frame.fingertips.fill(Vec3::Zero());
  r.steps[0].outputs = {12.0f, -0.0f, Limits::denorm_min()};
  const std::string text = r.format();
  EXPECT_NE(text.find(" 3 0x1.8p+3 -0x0p+0 0x0.000002p-126\n"), std::string::npos) << text;
  // What printf("%a") writes for the same values (as doubles) reads back as the same floats.
  std::vector<std::string> l = lines(text);
  std::string& step = l[l.size() - 2];
  const std::size_t outputs = step.rfind(" 3 ");
  std::string printed = " 3";
  for (float v : r.steps[0].outputs) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, " %a", static_cast<double>(v));
    printed += buffer;
  }
  step = step.substr(0, outputs) + printed;
  const SessionRecording back = SessionRecording::parse(join(l), "printf");
  for (int i = 0; i < 3; ++i) EXPECT_EQ(bits(back.steps[0].outputs[i]), bits(r.steps[0].outputs[i])) << printed;
}

TEST(SessionRecording, SettingsKeepTheirOrderAndAreFoundByKey) {
  std::mt19937 rng(3);
  const SessionRecording r = randomRecording(rng, 2);
  const SessionRecording back = SessionRecording::parse(r.format(), "settings");
  ASSERT_EQ(back.settings.size(), 4u);
  EXPECT_EQ(back.settings[0].first, "scene");
  ASSERT_NE(back.setting("scene"), nullptr);
  EXPECT_EQ(*back.setting("scene"), "poke liver #2");  // '#' inside a value is not a comment
  EXPECT_EQ(*back.setting("note"), "");
  EXPECT_EQ(back.setting("iterations"), nullptr);
}

TEST(SessionRecording, SettingsThatWouldNotReadBackAreRefusedAndLeaveTheFileAlone) {
  const std::filesystem::path path = testing::scratchPath("refused.session");
  SessionRecording good;
  good.settings = {{"scene", "jelly"}};
  good.save(path);
  const std::pair<std::string, std::string> bad[] = {
      {"", "x"}, {"two words", "x"}, {"key", "line\nbreak"}, {"key", " padded"}, {"key", "tab\there"}};
  for (const auto& setting : bad) {
    SessionRecording r = good;
    r.settings.push_back(setting);
    EXPECT_NE(errorOf([&] { r.save(path); }).find("setting"), std::string::npos) << setting.first;
    EXPECT_NE(errorOf([&] { SessionRecordingWriter(path, r.settings); }).find("setting"), std::string::npos);
  }
  SessionRecording twice = good;
  twice.settings.push_back({"scene", "other"});
  EXPECT_NE(errorOf([&] { twice.save(path); }).find("appears twice"), std::string::npos);
  EXPECT_EQ(SessionRecording::load(path).settings, good.settings);  // the earlier file, untouched
  std::filesystem::remove(path);
  // Nor is a half-written file left where the folder cannot be written.
  const std::filesystem::path nowhere = testing::scratchPath("no_such_dir") / "x.session";
  EXPECT_NE(errorOf([&] { good.save(nowhere); }).find("cannot write"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(nowhere.parent_path()));
}

TEST(SessionRecording, MalformedFilesNameTheLine) {
  std::mt19937 rng(8);
  SessionRecording r = randomRecording(rng, 3);
  r.settings.resize(1);
  for (auto& step : r.steps) step.outputs.resize(2);
  const std::vector<std::string> valid = lines(r.format());
  // Line 1 the tag, 2 the setting, 3 a comment, 4-6 the steps, 7 the end.
  ASSERT_EQ(valid.size(), 7u);
  ASSERT_EQ(valid[6], "end 3");
  ASSERT_NO_THROW(SessionRecording::parse(join(valid), "r.session"));

  struct Case {
    std::size_t line;  // 1-based, the line that is changed
    std::string replacement;
    std::size_t reported;  // the line the message names
    const char* what;
  };
  const std::string step1 = valid[4];
  const std::string withoutLast = step1.substr(0, step1.rfind(' '));
  const std::string cases_garbage = step1.substr(0, 10) + "\xff\xfe garbage" + step1.substr(10);
  const Case cases[] = {
      {1, "vrdeform-session 2", 1, "unsupported vrdeform-session version 2"},
      {1, "solid cube", 1, "not a session recording"},
      {5, withoutLast, 5, "says 2 outputs but has 1"},
      {5, step1.substr(0, 40), 5, "at least 35 fields"},
      {5, cases_garbage, 5, "expected a hexadecimal float"},
      {5, step1 + " 0x1p+0", 5, "says 2 outputs but has 3"},
      {5, "1 2" + step1.substr(3), 5, "'direct' is 0 or 1"},
      {5, "7" + step1.substr(1), 5, "step 7 where step 1 was expected"},
      {5, valid[5], 5, "step 2 where step 1 was expected"},
      {5, step1 + " # note", 5, "says 2 outputs but has 4"},
      {6, "setting late yes", 6, "settings must come before the first step"},
      {2, "setting", 2, "the key is missing"},
      {3, "setting scene again", 3, "appears twice"},
      {3, std::string("setting bell \x07"), 3, "control byte 0x07"},
      {7, "end 4", 7, "says 4 steps, but the file has 3"},
      {7, "end", 7, "expected 'end <step count>'"},
      {7, "end 3\n0 1", 8, "found after the 'end' line"},
      {7, "", 6, "ends without its 'end <step count>' line"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> text = valid;
    text[c.line - 1] = c.replacement;
    const std::string message = errorOf([&] { SessionRecording::parse(join(text), "r.session"); });
    const std::string where = "r.session:" + std::to_string(c.reported) + ":";
    EXPECT_EQ(message.rfind(where, 0), 0u) << c.what << " -> " << message;
    EXPECT_NE(message.find(c.what), std::string::npos) << message;
  }
  // A decimal number where a hexfloat belongs is refused too: it would not give back the same bits.
  std::vector<std::string> decimal = valid;
  decimal[3].replace(decimal[3].rfind(' ') + 1, std::string::npos, "1.5");
  EXPECT_NE(errorOf([&] { SessionRecording::parse(join(decimal), "r.session"); }).find("r.session:4: step 0, field 37"),
            std::string::npos);
  EXPECT_NE(errorOf([] { SessionRecording::parse("", "empty"); }).find("empty:1: empty file"), std::string::npos);
  EXPECT_NE(errorOf([] { SessionRecording::load(testing::scratchPath("absent.session")); }).find("absent.session"),
            std::string::npos);
}

TEST(SessionRecording, EveryTruncationIsDetected) {
  std::mt19937 rng(4);
  const std::string text = randomRecording(rng, 3).format();
  for (std::size_t n = 0; n + 1 < text.size(); ++n) {  // all but the final newline
    const std::string cut = text.substr(0, n);
    std::string message;
    try {
      SessionRecording::parse(cut, "cut");
    } catch (const Error& e) {
      message = e.what();
    }
    ASSERT_FALSE(message.empty()) << "a truncation at byte " << n << " of " << text.size() << " was read";
  }
  EXPECT_NO_THROW(SessionRecording::parse(text.substr(0, text.size() - 1), "no final newline"));
}

TEST(RecordingInput, ReplaysTheRecordedFramesInOrder) {
  std::mt19937 rng(9);
  SessionRecording r = randomRecording(rng, 5);
  const SessionRecording original = r;
  RecordingInput input(SessionRecording::parse(r.format(), "replay"));
  std::uint64_t step = 0;
  for (; !input.finished(step, 1e9); ++step) {  // the time is ignored
    ASSERT_LT(step, original.steps.size());
    EXPECT_EQ(difference(input.frame(step, -1.0), original.steps[step].frame), "") << step;
  }
  EXPECT_EQ(step, 5u);
  EXPECT_EQ(difference(input.frame(99, 0.0), original.steps[4].frame), "");  // the last one held

  RecordingInput empty{SessionRecording{}};
  EXPECT_TRUE(empty.finished(0, 0.0));
  HandFrame still;
  still.fingertips.fill(Vec3::Zero());
  EXPECT_EQ(difference(empty.frame(0, 0.0), still), "");
}

// Whatever bytes arrive, parse() returns a recording or throws vrd::Error.
TEST(SessionRecording, ArbitraryInputParsesOrThrowsError) {
  std::mt19937 rng(12);
  const std::string valid = randomRecording(rng, 4).format();
  const std::string alphabet = "0123456789abcdefxp.-+ #\n\tnaiends";
  int parsed = 0, rejected = 0;
  auto attempt = [&](const std::string& text) {
    try {
      SessionRecording::parse(text, "fuzz");
      ++parsed;
    } catch (const Error&) {
      ++rejected;
    }
  };
  for (int i = 0; i < 3000; ++i) attempt(testing::mutate(valid, rng, alphabet));
  for (int i = 0; i < 2000; ++i) {
    std::string text = i % 3 == 0 ? "vrdeform-session 1\n" : "";
    const std::size_t n = rng() % 300;
    for (std::size_t k = 0; k < n; ++k)
      text += i % 2 == 0 ? static_cast<char>(rng()) : alphabet[rng() % alphabet.size()];
    attempt(text);
  }
  testing::record("parsed", parsed);
  testing::record("rejected", rejected);
  EXPECT_GT(parsed, 0);
  EXPECT_GT(rejected, 0);
}

}  // namespace
}  // namespace vrd
