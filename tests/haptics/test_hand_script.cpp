// Scripted hand trajectories: keyframes interpolated as documented, every malformed file rejected
// with its line, and a script saved and loaded unchanged.
#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <numbers>
#include <random>
#include <string>

#include "test_support.h"
#include "vrdeform/interact/hand_script.h"

namespace vrd {
namespace {

using testing::errorOf;

// Identity to 90 degrees about z over 2 s, moving and closing the fingers.
constexpr const char* kTwoKeyframes = R"(vrdeform-hand-script 1
# t   x y z          qw qx qy qz                  thumb index middle ring little
0     0 0 0          1 0 0 0                      0 0 0 0 0
2     0.2 -0.4 0.6   0.70710678 0 0 0.70710678    1 0.5 0.25 0 1   # quarter turn
)";

float angleBetween(const Eigen::Matrix3f& a, const Eigen::Matrix3f& b) {
  return Eigen::AngleAxisf(a.transpose() * b).angle();
}

bool sameBits(float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); }

TEST(HandScript, SamplesAreTheKeyframesExactlyAtTheirTimes) {
  const HandScript script = HandScript::parse(kTwoKeyframes, "two.txt");
  ASSERT_EQ(script.keyframes().size(), 2u);
  EXPECT_EQ(script.duration(), 2.0);
  for (const HandKeyframe& k : script.keyframes()) {
    const HandPose pose = script.sample(k.time);
    EXPECT_EQ(pose.wrist.translation(), k.position);
    EXPECT_EQ(pose.wrist.linear(), k.orientation.toRotationMatrix());
    EXPECT_EQ(pose.closure, k.closure);
  }
  const HandKeyframe& last = script.keyframes()[1];
  EXPECT_EQ(last.position, Vec3(0.2f, -0.4f, 0.6f));
  EXPECT_NEAR(last.orientation.norm(), 1.0f, 1e-6f);
  EXPECT_EQ(last.closure, (std::array<float, 5>{1.0f, 0.5f, 0.25f, 0.0f, 1.0f}));
}

TEST(HandScript, PositionAndClosuresAreLinearBetweenKeyframes) {
  const HandScript script = HandScript::parse(kTwoKeyframes, "two.txt");
  for (double u : {0.25, 0.5, 0.75}) {
    const HandPose pose = script.sample(2.0 * u);
    const float s = static_cast<float>(u);
    EXPECT_LT((pose.wrist.translation() - s * Vec3(0.2f, -0.4f, 0.6f)).norm(), 1e-6f) << u;
    const std::array<float, 5> last{1.0f, 0.5f, 0.25f, 0.0f, 1.0f};
    for (int f = 0; f < kFingerCount; ++f) EXPECT_NEAR(pose.closure[f], s * last[f], 1e-6f) << u;
  }
}

TEST(HandScript, OrientationTurnsAtAConstantRateAlongTheShorterArc) {
  const HandScript script = HandScript::parse(kTwoKeyframes, "two.txt");
  const Eigen::Matrix3f start = Eigen::Matrix3f::Identity();
  for (double u : {0.25, 0.5, 0.75}) {
    const Eigen::Matrix3f r = script.sample(2.0 * u).wrist.linear();
    EXPECT_NEAR(angleBetween(start, r), u * std::numbers::pi / 2, 1e-5) << u;  // slerp, not a normalised lerp
    const Eigen::Vector3f axis = Eigen::AngleAxisf(r).axis();
    EXPECT_NEAR(axis.z(), 1.0f, 1e-5f);
  }
  // The same end orientation written as -q: still the quarter turn, not three quarters the other way.
  const HandScript flipped = HandScript::parse(
      "0 0 0 0  1 0 0 0  0 0 0\n"
      "2 0 0 0  -0.70710678 0 0 -0.70710678  0 0 0\n",
      "flipped.txt");
  EXPECT_NEAR(angleBetween(start, flipped.sample(1.0).wrist.linear()), std::numbers::pi / 4, 1e-5);
}

TEST(HandScript, HoldsTheEndsAndReadsNaNAsTheStart) {
  const HandScript script = HandScript::parse(kTwoKeyframes, "two.txt");
  const HandPose first = script.sample(0.0), last = script.sample(2.0);
  for (double t : {-1e300, -1.0, -0.0}) {
    EXPECT_EQ(script.sample(t).wrist.matrix(), first.wrist.matrix()) << t;
    EXPECT_EQ(script.sample(t).closure, first.closure) << t;
  }
  for (double t : {2.0 + 1e-9, 3.0, std::numeric_limits<double>::infinity()}) {
    EXPECT_EQ(script.sample(t).wrist.matrix(), last.wrist.matrix()) << t;
    EXPECT_EQ(script.sample(t).closure, last.closure) << t;
  }
  EXPECT_EQ(script.sample(std::nan("")).wrist.matrix(), first.wrist.matrix());
  EXPECT_EQ(script.sample(-std::numeric_limits<double>::infinity()).closure, first.closure);
}

TEST(HandScript, OneKeyframeIsAStillHand) {
  const HandScript script = HandScript::parse("1.5 0.1 0.2 0.3 1 0 0 0 0.5 0.5 0.5", "still.txt");
  EXPECT_EQ(script.duration(), 1.5);
  for (double t : {0.0, 1.5, 7.0}) EXPECT_EQ(script.sample(t).wrist.translation(), Vec3(0.1f, 0.2f, 0.3f));
}

TEST(HandScript, RingAndLittleFollowTheMiddleFingerWhenOmitted) {
  const HandScript script = HandScript::parse("0 0 0 0 1 0 0 0 0.1 0.2 0.3", "three.txt");
  EXPECT_EQ(script.keyframes()[0].closure, (std::array<float, 5>{0.1f, 0.2f, 0.3f, 0.3f, 0.3f}));
}

TEST(HandScript, QuaternionsAreNormalised) {
  const HandScript script = HandScript::parse("0 0 0 0 2 0 0 0 0 0 0\n1 0 0 0 1 1 0 0 0 0 0\n", "q.txt");
  EXPECT_EQ(script.keyframes()[0].orientation.coeffs(), Quat::Identity().coeffs());
  const Quat q = script.keyframes()[1].orientation;
  EXPECT_NEAR(q.w(), std::sqrt(0.5f), 1e-7f);
  EXPECT_NEAR(q.x(), std::sqrt(0.5f), 1e-7f);
}

TEST(HandScript, ParseErrorsNameTheLine) {
  struct Case {
    const char* text;
    const char* where;  // "name:line:"
    const char* what;
  };
  const char* ok = "0 0 0 0 1 0 0 0 0 0 0\n";
  const Case cases[] = {
      {"0 0 0 0 1 0 0 0 0 0\n", "s.txt:1:", "11 or 13 fields"},
      {"0 0 0 0 1 0 0 0 0 0 0 0\n", "s.txt:1:", "found 12"},
      {"# comment\n\n0 0 0 0 1 0 0 0 0 0 0\n1 0 0 x 1 0 0 0 0 0 0\n", "s.txt:4:", "z is not a number: 'x'"},
      {"0,5 0 0 0 1 0 0 0 0 0 0\n", "s.txt:1:", "time is not a number"},
      {"0 0 0 0 1 0 0 0 0 0 0\n1 nan 0 0 1 0 0 0 0 0 0\n", "s.txt:2:", "x is nan; numbers must be finite"},
      {"0 0 0 1e39 1 0 0 0 0 0 0\n", "s.txt:1:", "z is 1e39"},
      {"inf 0 0 0 1 0 0 0 0 0 0\n", "s.txt:1:", "time is inf"},
      {"1e400 0 0 0 1 0 0 0 0 0 0\n", "s.txt:1:", "time is inf"},
      {"0 0 0 0 1 0 0 0 0 0 0\n0 0 0 0 1 0 0 0 0 0 0\n", "s.txt:2:", "not after the previous"},
      {"1 0 0 0 1 0 0 0 0 0 0\n\n0.5 0 0 0 1 0 0 0 0 0 0\n", "s.txt:3:", "not after the previous"},
      {"0 0 0 0 0 0 0 0 0 0 0\n", "s.txt:1:", "not a rotation"},
      {"0 0 0 0 1e-30 0 0 0 0 0 0\n", "s.txt:1:", "not a rotation"},
      {"0 0 0 0 1 0 0 0 0 1.5 0\n", "s.txt:1:", "index closure 1.5 is outside [0, 1]"},
      {"0 0 0 0 1 0 0 0 0 0 0 -0.1 0\n", "s.txt:1:", "ring closure -0.1 is outside"},
      {"", "s.txt:1:", "no keyframes"},
      {"# only a comment\n\n", "s.txt:2:", "no keyframes"},
      {"vrdeform-hand-script 1\n", "s.txt:1:", "no keyframes"},
      {"vrdeform-hand-script 2\n0 0 0 0 1 0 0 0 0 0 0\n", "s.txt:1:", "unsupported vrdeform-hand-script version 2"},
      {"vrdeform-hand-script\n", "s.txt:1:", "expected 'vrdeform-hand-script 1'"},
      {"vrdeform-hand-script one\n", "s.txt:1:", "expected 'vrdeform-hand-script 1'"},
      {"0 0 0 0 1 0 0 0 0 0 0\nvrdeform-hand-script 1\n", "s.txt:2:", "only be the first line"},
      {"0 0 0 0 1 0 0 0 0 0 0\n1 0 0 0 1 0 0 0 0 0 \x01\n", "s.txt:2:", "middle is not a number: '\\x01'"},
  };
  for (const Case& c : cases) {
    const std::string message = errorOf([&] { HandScript::parse(c.text, "s.txt"); });
    EXPECT_EQ(message.rfind(c.where, 0), 0u) << c.text << " -> " << message;
    EXPECT_NE(message.find(c.what), std::string::npos) << c.text << " -> " << message;
  }
  EXPECT_NO_THROW(HandScript::parse(ok, "s.txt"));
}

TEST(HandScript, ConstructorChecksLikeTheParser) {
  EXPECT_NE(errorOf([] { HandScript(std::vector<HandKeyframe>{}); }).find("no keyframes"), std::string::npos);
  std::vector<HandKeyframe> keys(2);
  keys[1].time = 1.0;
  keys[1].closure[4] = 2.0f;
  EXPECT_NE(errorOf([&] { HandScript{keys}; }).find("keyframe 1: little closure 2"), std::string::npos);
  keys[1].closure[4] = 1.0f;
  keys[1].orientation = Quat(0, 0, 0, 0);
  EXPECT_NE(errorOf([&] { HandScript{keys}; }).find("keyframe 1: orientation"), std::string::npos);
  keys[1].orientation = Quat(0, 0, 0, 3);  // normalised, like the parser does
  EXPECT_EQ(HandScript(keys).keyframes()[1].orientation.coeffs(), Quat(0, 0, 0, 1).coeffs());
  keys[1].time = 0.0;
  EXPECT_NE(errorOf([&] { HandScript{keys}; }).find("keyframe 1: time 0 is not after"), std::string::npos);
}

TEST(HandScript, SaveAndLoadGiveBackIdenticalKeyframes) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<float> closure(0.0f, 1.0f);
  std::vector<HandKeyframe> keys(40);
  double t = -0.5;
  const float scales[] = {1.0f, 1e-3f, 1e-30f, 1e20f, 0.0f};
  for (std::size_t i = 0; i < keys.size(); ++i) {
    HandKeyframe& k = keys[i];
    k.time = t += std::abs(unit(rng)) + 1e-3;
    const float scale = scales[i % 5];
    k.position = scale * Vec3(float(unit(rng)), float(unit(rng)), float(unit(rng)));
    if (i % 5 == 4) k.position.x() = -0.0f;
    k.orientation = Quat(float(unit(rng)), float(unit(rng)), float(unit(rng)), float(unit(rng)));
    for (float& c : k.closure) c = closure(rng);
    k.closure[i % 5] = float(i % 2);  // the ends of the range
  }
  const HandScript script(keys);
  const std::filesystem::path path = testing::scratchPath("round_trip.hand");
  script.save(path);
  const HandScript loaded = HandScript::load(path);
  std::filesystem::remove(path);
  ASSERT_EQ(loaded.keyframes().size(), keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const HandKeyframe &a = script.keyframes()[i], &b = loaded.keyframes()[i];
    EXPECT_EQ(std::bit_cast<std::uint64_t>(a.time), std::bit_cast<std::uint64_t>(b.time)) << i;
    for (int j = 0; j < 3; ++j) EXPECT_TRUE(sameBits(a.position[j], b.position[j])) << i;
    for (int j = 0; j < 4; ++j) EXPECT_TRUE(sameBits(a.orientation.coeffs()[j], b.orientation.coeffs()[j])) << i;
    for (int j = 0; j < kFingerCount; ++j) EXPECT_TRUE(sameBits(a.closure[j], b.closure[j])) << i;
  }
  EXPECT_EQ(loaded.format(), script.format());
}

TEST(HandScript, LoadNamesAMissingFile) {
  const std::filesystem::path path = testing::scratchPath("missing.hand");
  EXPECT_NE(errorOf([&] { HandScript::load(path); }).find(path.string()), std::string::npos);
}

TEST(HandScriptInput, FollowsTheClockAndFinishesAfterTheLastKeyframe) {
  HandScriptInput input(HandScript::parse(kTwoKeyframes, "two.txt"));
  const HandFrame frame = input.frame(123, 1.0);
  EXPECT_FALSE(frame.direct);
  for (const Vec3& tip : frame.fingertips) EXPECT_EQ(tip, Vec3::Zero());  // defined, so recordings reproduce
  EXPECT_EQ(frame.pose.wrist.matrix(), input.script().sample(1.0).wrist.matrix());
  EXPECT_FALSE(input.finished(0, 0.0));
  EXPECT_FALSE(input.finished(1000, 2.0));
  EXPECT_TRUE(input.finished(0, 2.001));
  EXPECT_TRUE(input.finished(0, std::nan("")));  // never an endless loop
}

// Whatever bytes arrive, parse() returns a valid script or throws vrd::Error.
TEST(HandScript, ArbitraryInputParsesOrThrowsError) {
  std::mt19937 rng(5);
  const std::string valid = HandScript::parse(kTwoKeyframes, "two.txt").format() + "3 0 0 0 0 1 0 0 1 1 1 1 1\n";
  const std::string alphabet = "0123456789.-+eE #\n\t naifx";
  int parsed = 0, rejected = 0;
  auto attempt = [&](const std::string& text) {
    try {
      const HandScript script = HandScript::parse(text, "fuzz");
      for (std::size_t i = 0; i < script.keyframes().size(); ++i) {
        const HandKeyframe& k = script.keyframes()[i];
        ASSERT_TRUE(std::isfinite(k.time) && isFinite(k.position));
        ASSERT_NEAR(k.orientation.norm(), 1.0f, 1e-5f);
        if (i > 0) {
          ASSERT_GT(k.time, script.keyframes()[i - 1].time);
        }
        for (float c : k.closure) ASSERT_TRUE(c >= 0.0f && c <= 1.0f);
      }
      ++parsed;
    } catch (const Error&) {
      ++rejected;
    }
  };
  for (std::size_t n = 0; n <= valid.size(); ++n) attempt(valid.substr(0, n));  // every truncation
  for (int i = 0; i < 3000; ++i) attempt(testing::mutate(valid, rng, alphabet));
  for (int i = 0; i < 2000; ++i) {
    std::string text(rng() % 200, '\0');
    const bool bytes = i % 2 == 0;
    for (char& c : text) c = bytes ? static_cast<char>(rng()) : alphabet[rng() % alphabet.size()];
    attempt(text);
  }
  testing::record("parsed", parsed);
  testing::record("rejected", rejected);
  EXPECT_GT(parsed, 0);
  EXPECT_GT(rejected, 0);
}

}  // namespace
}  // namespace vrd
