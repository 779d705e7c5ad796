// The WEART middleware wire protocol (weart_protocol.h): every message example quoted in the protocol
// notes (../shared/reference/weart-protocol.md) parses to its values, every frame either side writes
// reads back on the other, the frame splitter gives the same frames however the stream is cut, and
// no malformed frame crashes a parser or is read as something it is not.
//
// The corpus tests/fuzz_corpus/weart holds one frame per file (no '~'), and seeds the libFuzzer target
// (scripts/fuzz.sh). A file's name says what both parsers must make of it:
//   ok_mw_*      parseMiddlewareFrame gives a known message;  parseClientFrame an error
//   ok_client_*  parseClientFrame gives a command;            parseMiddlewareFrame an error or Unknown
//   unknown_*    parseMiddlewareFrame gives Unknown;          parseClientFrame an error
//   bad_client_* parseClientFrame gives an error;             parseMiddlewareFrame an error or Unknown
//   bad_*        both parsers give an error
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <clocale>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <locale>
#include <map>
#include <random>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "test_support.h"
#include "vrdeform/devices/weart_protocol.h"

namespace vrd::weart {
namespace {

constexpr std::size_t idx(Point p) { return static_cast<std::size_t>(p); }
constexpr HandSide kHands[] = {HandSide::Left, HandSide::Right};
constexpr Point kPoints[] = {Point::Thumb, Point::Index, Point::Middle, Point::Annular, Point::Pinky, Point::Palm};

std::string printable(std::string_view s) {
  std::string out;
  for (const char c : s.substr(0, 120)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  return out + (s.size() > 120 ? "..." : "");
}

/// The message of type T that `frame` parses to (a test failure and T{} otherwise).
template <typename T>
T messageOf(std::string_view frame) {
  const ParsedMiddleware p = parseMiddlewareFrame(frame);
  EXPECT_EQ(p.error, "") << printable(frame);
  if (!p.message || !std::holds_alternative<T>(*p.message)) {
    ADD_FAILURE() << "not the expected message: " << printable(frame);
    return T{};
  }
  return std::get<T>(*p.message);
}

ClientCommand commandOf(std::string_view frame) {
  const ParsedClient p = parseClientFrame(frame);
  EXPECT_EQ(p.error, "") << printable(frame);
  if (!p.command) {
    ADD_FAILURE() << "no command: " << printable(frame);
    return {};
  }
  return *p.command;
}

/// Expects parseMiddlewareFrame to reject `frame`, and returns its error.
std::string middlewareError(std::string_view frame) {
  const ParsedMiddleware p = parseMiddlewareFrame(frame);
  EXPECT_FALSE(p.message.has_value()) << "accepted: " << printable(frame);
  EXPECT_NE(p.error, "") << printable(frame);
  return p.error;
}

std::string clientError(std::string_view frame) {
  const ParsedClient p = parseClientFrame(frame);
  EXPECT_FALSE(p.command.has_value()) << "accepted: " << printable(frame);
  EXPECT_NE(p.error, "") << printable(frame);
  return p.error;
}

std::vector<std::string> split(FrameSplitter& splitter, const std::vector<std::string_view>& chunks) {
  std::vector<std::string> frames;
  for (const auto chunk : chunks) splitter.feed(chunk, frames);
  return frames;
}

std::vector<std::string> splitAll(std::string_view stream) {
  FrameSplitter splitter;
  return split(splitter, {stream});
}

bool isAscii(std::string_view s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return c >= 0x20 && c < 0x7f; });
}

// --- Names -----------------------------------------------------------------------------------------

TEST(WeartProtocol, WireNamesReadBackAndAreUpperCaseOnly) {
  for (const HandSide h : kHands) EXPECT_EQ(handSideFromWire(wireName(h)), h);
  for (const Point p : kPoints) EXPECT_EQ(pointFromWire(wireName(p)), p);
  EXPECT_EQ(wireName(HandSide::Left), "LEFT");
  EXPECT_EQ(wireName(Point::Annular), "ANNULAR");
  for (const char* bad : {"left", "Right", "", "RIGHT ", "BOTH"}) EXPECT_FALSE(handSideFromWire(bad)) << bad;
  for (const char* bad : {"thumb", "RING", "", "PALM\n"}) EXPECT_FALSE(pointFromWire(bad)) << bad;
}

// --- FrameSplitter ---------------------------------------------------------------------------------

TEST(WeartFrameSplitter, ManyFramesInOneFeedTrimmedWithoutEmptyOnes) {
  const auto frames = splitAll("exit~~ CalibrationStatus:1:1\r\n~\t~{\"type\":\"X\",\"ts\":1}~~~disconnect~");
  EXPECT_EQ(frames,
            (std::vector<std::string>{"exit", "CalibrationStatus:1:1", "{\"type\":\"X\",\"ts\":1}", "disconnect"}));
}

TEST(WeartFrameSplitter, KeepsTheTailUntilItsTerminator) {
  FrameSplitter splitter;
  std::vector<std::string> frames;
  splitter.feed("Tracking:TrackType1:1:2", frames);
  EXPECT_TRUE(frames.empty());
  EXPECT_EQ(splitter.buffered(), 23u);
  splitter.feed(":3:4:5:6:7:8", frames);
  EXPECT_TRUE(frames.empty());
  splitter.feed("~exit", frames);
  EXPECT_EQ(frames, std::vector<std::string>{"Tracking:TrackType1:1:2:3:4:5:6:7:8"});
  EXPECT_EQ(splitter.buffered(), 4u);  // "exit", no terminator yet
  splitter.reset();
  EXPECT_EQ(splitter.buffered(), 0u);
  splitter.feed("~", frames);
  EXPECT_EQ(frames.size(), 1u);  // the reset tail is gone, and "" is no frame
}

// A realistic stream: every frame type, packed, with empty frames and stray whitespace.
std::string sampleStream() {
  MiddlewareStatus status;
  status.status = "RUNNING";
  status.connectedDevices.push_back({"AA:BB:CC:DD:EE:01", HandSide::Right});
  HandTracking hand;
  hand.closure.fill(0.25f);
  return statusFrame(status, 1717600000123) + "~" + trackingG1Frame({hand}) + " \r\n" +
         trackingG2Frame(hand, 1717600000456) + calibrationStatusFrame(HandSide::Left, 2) + "~~" +
         forceFrame(HandSide::Right, Point::Index, 0.8f) + requestFrame("MW_GET_STATUS", 7) + "exit~" + "partial";
}

TEST(WeartFrameSplitter, AFrameSplitAtEveryBytePositionComesOutWhole) {
  const std::string stream = sampleStream();
  const auto expected = splitAll(stream);
  ASSERT_EQ(expected.size(), 7u);
  for (std::size_t i = 0; i <= stream.size(); ++i) {
    FrameSplitter splitter;
    const std::string_view s(stream);
    EXPECT_EQ(split(splitter, {s.substr(0, i), s.substr(i)}), expected) << "split at " << i;
    EXPECT_EQ(splitter.buffered(), 7u);  // "partial"
  }
  FrameSplitter bytewise;
  std::vector<std::string> frames;
  for (const char c : stream) bytewise.feed(std::string_view(&c, 1), frames);
  EXPECT_EQ(frames, expected);
}

TEST(WeartFrameSplitter, RandomChunksGiveTheSameFrames) {
  const std::string stream = sampleStream() + "~" + sampleStream();
  const auto expected = splitAll(stream);
  std::mt19937 rng(5);
  for (int trial = 0; trial < 300; ++trial) {
    FrameSplitter splitter;
    std::vector<std::string> frames;
    for (std::size_t at = 0; at < stream.size();) {
      const std::size_t n = std::min<std::size_t>(rng() % 40, stream.size() - at);  // empty feeds too
      splitter.feed(std::string_view(stream).substr(at, n), frames);
      at += n;
    }
    ASSERT_EQ(frames, expected) << "trial " << trial;
  }
}

TEST(WeartFrameSplitter, TenMegabytesWithoutTerminatorKeepMemoryBounded) {
  constexpr std::size_t kCap = 1 << 20;
  const std::string chunk(64 * 1024, 'x');
  FrameSplitter splitter;
  std::vector<std::string> frames;
  std::size_t most = 0;
  for (std::size_t sent = 0; sent < 10 * 1000 * 1000; sent += chunk.size()) {
    splitter.feed(chunk, frames);
    most = std::max(most, splitter.buffered());
  }
  EXPECT_LE(most, kCap);
  EXPECT_EQ(splitter.buffered(), 0u);  // the over-long frame is being skipped, not stored
  EXPECT_TRUE(frames.empty());
  EXPECT_EQ(splitter.dropped(), 1u);
  splitter.feed("xxx~exit~CalibrationResult:1:0~", frames);  // the end of the junk, then good frames
  EXPECT_EQ(frames, (std::vector<std::string>{"exit", "CalibrationResult:1:0"}));
  EXPECT_EQ(splitter.dropped(), 1u);

  FrameSplitter once;  // the same in one feed
  frames.clear();
  once.feed(std::string(10 * 1000 * 1000, 'y') + "~exit~", frames);
  EXPECT_EQ(frames, std::vector<std::string>{"exit"});
  EXPECT_EQ(once.dropped(), 1u);
  vrd::testing::record("max_buffered_bytes", static_cast<double>(most));
}

TEST(WeartFrameSplitter, AFrameOverTheCapIsDroppedWholeEvenWhenTerminated) {
  FrameSplitter splitter(16);
  std::vector<std::string> frames;
  splitter.feed("0123456789abcdef~0123456789abcdefg~exit~", frames);  // 16 bytes pass, 17 do not
  EXPECT_EQ(frames, (std::vector<std::string>{"0123456789abcdef", "exit"}));
  EXPECT_EQ(splitter.dropped(), 1u);
  frames.clear();
  splitter.feed("0123456789", frames);  // over the cap across two feeds
  splitter.feed("abcdefghij", frames);
  EXPECT_EQ(splitter.buffered(), 0u);
  splitter.feed("klm~disconnect~", frames);
  EXPECT_EQ(frames, std::vector<std::string>{"disconnect"});
  EXPECT_EQ(splitter.dropped(), 2u);
}

// --- The protocol notes' examples --------------------------------------------------------------------

TEST(WeartExamples, ClientFramesOfSection6) {
  ClientCommand c = commandOf("StartFromClient:SdkLLCPP:2.0.0:TrackType1~");
  EXPECT_EQ(c.kind, ClientCommand::Kind::Start);
  EXPECT_EQ(c.sdkType, "SdkLLCPP");
  EXPECT_EQ(c.sdkVersion, "2.0.0");
  EXPECT_EQ(c.text, "TrackType1");
  c = commandOf("StartFromClient:SdkLLCsharp:2.0.1:TrackType1~");
  EXPECT_EQ(c.sdkType, "SdkLLCsharp");
  EXPECT_EQ(c.sdkVersion, "2.0.1");
  c = commandOf("StartFromClient~");
  EXPECT_EQ(c.kind, ClientCommand::Kind::Start);
  EXPECT_EQ(c.text, "");
  EXPECT_EQ(commandOf("StopFromClient~").kind, ClientCommand::Kind::Stop);
  EXPECT_EQ(commandOf("StartCalibration~").kind, ClientCommand::Kind::StartCalibration);
  EXPECT_EQ(commandOf("StopCalibration~").kind, ClientCommand::Kind::StopCalibration);
  EXPECT_EQ(commandOf("ResetCalibration~").kind, ClientCommand::Kind::ResetCalibration);

  for (const char* frame : {"temperature:0.200000:RIGHT:INDEX~", "temperature:0.2:RIGHT:INDEX~"}) {
    c = commandOf(frame);
    EXPECT_EQ(c.kind, ClientCommand::Kind::Temperature);
    EXPECT_FLOAT_EQ(c.value, 0.2f);
    EXPECT_EQ(c.hand, HandSide::Right);
    EXPECT_EQ(c.point, Point::Index);
  }
  c = commandOf("stopTemperature:RIGHT:INDEX~");
  EXPECT_EQ(c.kind, ClientCommand::Kind::StopTemperature);
  EXPECT_EQ(c.point, Point::Index);

  for (const char* frame : {"force:0.800000:0.000000:0.000000:RIGHT:INDEX~", "force:0.8:0.0:0.0:RIGHT:INDEX~",
                            "force:0.8:0.8:0.8:RIGHT:INDEX~", "force:0.8:0.0:0.0:RIGHT:INDEX"}) {
    c = commandOf(frame);
    EXPECT_EQ(c.kind, ClientCommand::Kind::Force);
    EXPECT_FLOAT_EQ(c.value, 0.8f) << frame;
    EXPECT_EQ(c.hand, HandSide::Right);
    EXPECT_EQ(c.point, Point::Index);
  }
  c = commandOf("stopForce:LEFT:THUMB~");
  EXPECT_EQ(c.kind, ClientCommand::Kind::StopForce);
  EXPECT_EQ(c.hand, HandSide::Left);
  EXPECT_EQ(c.point, Point::Thumb);

  for (const char* frame :
       {"texture:9:0.500000:0.000000:0.500000:100.000000:RIGHT:INDEX~", "texture:9:0.5:0:0.5:100:RIGHT:INDEX~"}) {
    c = commandOf(frame);
    EXPECT_EQ(c.kind, ClientCommand::Kind::Texture);
    EXPECT_EQ(c.textureIndex, 9);
    EXPECT_FLOAT_EQ(c.value, 0.5f);
    EXPECT_FLOAT_EQ(c.volume, 100.0f);
    EXPECT_EQ(c.hand, HandSide::Right);
    EXPECT_EQ(c.point, Point::Index);
  }
  c = commandOf("stopTexture:RIGHT:INDEX~");
  EXPECT_EQ(c.kind, ClientCommand::Kind::StopTexture);

  for (const char* type : {"MW_GET_STATUS", "DEVICES_GET_STATUS", "RAW_DATA_ON", "RAW_DATA_OFF"}) {
    c = commandOf("{\"type\":\"" + std::string(type) + "\",\"ts\":1717600000000}~");
    EXPECT_EQ(c.kind, ClientCommand::Kind::Request);
    EXPECT_EQ(c.text, type);
    EXPECT_EQ(c.timestampMs, 1717600000000u);
  }
  // §2.1: the key orders and spacings of the C++, C# and Python SDKs.
  for (const char* frame :
       {R"({"ts":1717600000000,"type":"MW_GET_STATUS"})", R"({"ts":1717600000000,"type":"MW_GET_STATUS","data":{}})",
        R"({"type": "MW_GET_STATUS", "ts": 1717600000000})"}) {
    c = commandOf(frame);
    EXPECT_EQ(c.text, "MW_GET_STATUS") << frame;
    EXPECT_EQ(c.timestampMs, 1717600000000u);
  }
}

TEST(WeartExamples, CalibrationAndSessionFramesOfSection7) {
  auto status = messageOf<CalibrationStatus>("CalibrationStatus:1:1~");
  EXPECT_EQ(status.hand, HandSide::Right);
  EXPECT_EQ(status.status, 1);
  status = messageOf<CalibrationStatus>("CalibrationStatus:1:2~");
  EXPECT_EQ(status.status, 2);
  auto result = messageOf<CalibrationResult>("CalibrationResult:1:0~");
  EXPECT_EQ(result.hand, HandSide::Right);
  EXPECT_TRUE(result.success);  // 0 means success (§7.2)
  result = messageOf<CalibrationResult>("CalibrationResult:0:1~");
  EXPECT_EQ(result.hand, HandSide::Left);
  EXPECT_FALSE(result.success);
  messageOf<Exit>("exit~");
  messageOf<Disconnect>("disconnect~");
}

TEST(WeartExamples, G1TrackingInBothOrders) {
  // §7.3.2: right index 200, thumb 128, thumb abduction 110, middle 190; left all 0.
  Tracking t = messageOf<Tracking>("Tracking:TrackType1:200:128:110:190:0:0:0:0~");
  ASSERT_EQ(t.hands.size(), 2u);
  const HandTracking& right = t.hands[0];
  EXPECT_EQ(right.hand, HandSide::Right);
  EXPECT_FLOAT_EQ(right.closure[idx(Point::Index)], 200.0f / 255.0f);
  EXPECT_FLOAT_EQ(right.closure[idx(Point::Thumb)], 128.0f / 255.0f);
  EXPECT_FLOAT_EQ(right.thumbAbduction, 110.0f / 255.0f);
  EXPECT_FLOAT_EQ(right.closure[idx(Point::Middle)], 190.0f / 255.0f);
  for (const Point p : {Point::Annular, Point::Pinky, Point::Palm}) EXPECT_TRUE(std::isnan(right.closure[idx(p)]));
  EXPECT_FALSE(right.wristQuaternion);
  const HandTracking& left = t.hands[1];
  EXPECT_EQ(left.hand, HandSide::Left);
  for (const Point p : {Point::Thumb, Point::Index, Point::Middle}) EXPECT_EQ(left.closure[idx(p)], 0.0f);
  EXPECT_EQ(left.thumbAbduction, 0.0f);

  // §7.3.1, legacy DEFAULT: R thumb, index, middle, palm, then the left hand; no abduction.
  t = messageOf<Tracking>("Tracking:10:20:30:40:50:60:70:80~");
  ASSERT_EQ(t.hands.size(), 2u);
  const float expected[2][4] = {{10, 20, 30, 40}, {50, 60, 70, 80}};
  for (std::size_t h = 0; h < 2; ++h) {
    const HandTracking& hand = t.hands[h];
    EXPECT_EQ(hand.hand, h == 0 ? HandSide::Right : HandSide::Left);
    const Point order[] = {Point::Thumb, Point::Index, Point::Middle, Point::Palm};
    for (std::size_t i = 0; i < 4; ++i) EXPECT_FLOAT_EQ(hand.closure[idx(order[i])], expected[h][i] / 255.0f);
    EXPECT_TRUE(std::isnan(hand.closure[idx(Point::Annular)]));
    EXPECT_TRUE(std::isnan(hand.closure[idx(Point::Pinky)]));
    EXPECT_TRUE(std::isnan(hand.thumbAbduction));
  }
  t = messageOf<Tracking>("Tracking:TrackType1:255:0:255:0:1:2:3:4");  // the extremes
  EXPECT_EQ(t.hands[0].closure[idx(Point::Index)], 1.0f);
  EXPECT_EQ(t.hands[0].thumbAbduction, 1.0f);
}

TEST(WeartExamples, ProTrackingOfSection7_4) {
  const auto p = parseMiddlewareFrame(
      R"({"type":"TRACKING_BENDING_G2","ts":1717600000456,"data":{"handSide":"RIGHT","thumb":{"closure":0.31,"abduction":0.44},"index":{"closure":0.72,"abduction":0.0},"middle":{"closure":0.65,"abduction":0.0},"annular":{"closure":0.60,"abduction":0.0},"pinky":{"closure":0.55,"abduction":0.0},"palm":{"closure":0.0,"abduction":0.0},"wrist":{"quaternion":{"x":0.0,"y":0.0,"z":0.0,"w":1.0}}}}~)");
  ASSERT_EQ(p.error, "");
  EXPECT_EQ(p.timestampMs, 1717600000456u);
  const Tracking& t = std::get<Tracking>(*p.message);
  ASSERT_EQ(t.hands.size(), 1u);
  const HandTracking& h = t.hands[0];
  EXPECT_EQ(h.hand, HandSide::Right);
  const float closures[] = {0.31f, 0.72f, 0.65f, 0.60f, 0.55f, 0.0f};
  for (const Point pt : kPoints) EXPECT_FLOAT_EQ(h.closure[idx(pt)], closures[idx(pt)]);
  EXPECT_FLOAT_EQ(h.thumbAbduction, 0.44f);
  ASSERT_TRUE(h.wristQuaternion);
  EXPECT_EQ(*h.wristQuaternion, (std::array<float, 4>{0.0f, 0.0f, 0.0f, 1.0f}));
}

constexpr const char* kMwStatusExample =
    R"({"type":"MW_STATUS","ts":1717600000123,"data":{"status":"RUNNING","version":"1.4.0","statusCode":0,"errorDesc":"","warningCode":0,"warningDesc":"","actuationsEnabled":true,"connectedDevices":[{"macAddress":"AA:BB:CC:DD:EE:01","handSide":"RIGHT"}]}}~)";
constexpr const char* kWaStatusExample =
    R"({"type":"WA_STATUS","ts":1717600000123,"data":{"status":"IDLE","version":"2.0.0","statusCode":0,"errorDesc":"","warningCode":0,"warningDesc":"","actuationsEnabled":true,"connectionType":"BLE","autoconnection":true,"deviceSelection":"PhysicalDevices","trackingPlayback":false,"rawDataLog":false,"sensorOnMask":false,"connectedDevices":[{"macAddress":"AA:BB:CC:DD:EE:02","handSide":"LEFT"}]}}~)";
constexpr const char* kDevicesStatusExample =
    R"({"type":"DEVICES_STATUS","ts":1717600000124,"data":{"devices":[{"macAddress":"AA:BB:CC:DD:EE:01","handSide":"RIGHT","batteryLevel":85,"charging":false,"thimbles":[{"id":"THUMB","connected":true,"statusCode":0,"errorDesc":""},{"id":"INDEX","connected":true,"statusCode":0,"errorDesc":""},{"id":"MIDDLE","connected":true,"statusCode":0,"errorDesc":""}]}]}}~)";
constexpr const char* kProStatusExample =
    R"({"type":"WEART_TD_PRO_STATUS","ts":1717600000125,"data":{"devices":[{"macAddress":"AA:BB:CC:DD:EE:02","handSide":"LEFT","signalStrength":-60.5,"sensorsCalibDate":"2026-02-03T09:03:03Z","master":{"batteryLevel":90,"charging":false,"chargeCompleted":false,"connection":{"bluetoothOn":true,"bluetoothConnected":true,"wifiOn":false,"wifiConnected":false,"usbConnected":false},"imuFault":false,"adcFault":false,"buttonPushed":false},"nodes":[{"id":"THUMB","connected":true,"imuFault":false,"adcFault":false,"tofFault":true},{"id":"PALM","connected":true,"imuFault":false,"adcFault":false,"tofFault":true}]}]}}~)";

TEST(WeartExamples, StatusFramesOfSections7_5To7_8) {
  auto p = parseMiddlewareFrame(kMwStatusExample);
  ASSERT_EQ(p.error, "");
  EXPECT_EQ(p.timestampMs, 1717600000123u);
  const auto mw = std::get<MiddlewareStatus>(*p.message);
  EXPECT_FALSE(mw.pro);
  EXPECT_EQ(mw.status, "RUNNING");
  EXPECT_EQ(mw.version, "1.4.0");
  EXPECT_EQ(mw.statusCode, 0);
  EXPECT_TRUE(mw.actuationsEnabled);
  ASSERT_EQ(mw.connectedDevices.size(), 1u);
  EXPECT_EQ(mw.connectedDevices[0].macAddress, "AA:BB:CC:DD:EE:01");
  EXPECT_EQ(mw.connectedDevices[0].hand, HandSide::Right);

  const auto wa = messageOf<MiddlewareStatus>(kWaStatusExample);
  EXPECT_TRUE(wa.pro);
  EXPECT_EQ(wa.status, "IDLE");
  EXPECT_EQ(wa.connectionType, "BLE");
  EXPECT_TRUE(wa.autoconnection);
  EXPECT_EQ(wa.deviceSelection, "PhysicalDevices");
  EXPECT_FALSE(wa.trackingPlayback || wa.rawDataLog || wa.sensorOnMask);
  ASSERT_EQ(wa.connectedDevices.size(), 1u);
  EXPECT_EQ(wa.connectedDevices[0].hand, HandSide::Left);

  const auto g1 = messageOf<DevicesStatus>(kDevicesStatusExample);
  EXPECT_FALSE(g1.pro);
  ASSERT_EQ(g1.devices.size(), 1u);
  EXPECT_EQ(g1.devices[0].batteryLevel, 85);
  EXPECT_FALSE(g1.devices[0].charging);
  ASSERT_EQ(g1.devices[0].nodes.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(g1.devices[0].nodes[i].point, kPoints[i]);
    EXPECT_TRUE(g1.devices[0].nodes[i].connected);
  }

  const auto pro = messageOf<DevicesStatus>(kProStatusExample);
  EXPECT_TRUE(pro.pro);
  ASSERT_EQ(pro.devices.size(), 1u);
  EXPECT_EQ(pro.devices[0].hand, HandSide::Left);
  EXPECT_EQ(pro.devices[0].batteryLevel, 90);
  ASSERT_EQ(pro.devices[0].nodes.size(), 2u);
  EXPECT_EQ(pro.devices[0].nodes[1].point, Point::Palm);
  EXPECT_EQ(pro.devices[0].signalStrength, -60.5);
  EXPECT_EQ(pro.devices[0].sensorsCalibDate, "2026-02-03T09:03:03Z");
  const DevicesStatus::Connection& link = pro.devices[0].connection;
  EXPECT_TRUE(link.bluetoothOn && link.bluetoothConnected);
  EXPECT_FALSE(link.wifiOn || link.wifiConnected || link.usbConnected);
}

TEST(WeartExamples, RawDataFramesOfSections7_9To7_11) {
  const auto raw = messageOf<RawData>(
      R"({"type":"RAW_DATA","ts":1717600000500,"data":{"handSide":"RIGHT","index":{"accelerometer":{"x":0.01,"y":-0.98,"z":0.05},"gyroscope":{"x":0.3,"y":-1.2,"z":0.0},"timeOfFlight":{"distance":42}},"palm":{"accelerometer":{"x":0.0,"y":-1.0,"z":0.0},"gyroscope":{"x":0.0,"y":0.0,"z":0.0},"timeOfFlight":{"distance":0}}}}~)");
  EXPECT_EQ(raw.type, "RAW_DATA");
  EXPECT_EQ(raw.hand, HandSide::Right);
  EXPECT_EQ(raw.points, (std::vector<Point>{Point::Index, Point::Palm}));
  EXPECT_EQ(messageOf<RawData>(R"({"type":"RAW_DATA_TD_PRO","ts":1,"data":{"handSide":"LEFT"}})").hand, HandSide::Left);
  EXPECT_EQ(messageOf<RawData>(R"({"type":"RAW_SENSOR_ON_MASK","ts":1,"data":{"handSide":"RIGHT"}})").type,
            "RAW_SENSOR_ON_MASK");
}

// --- Round trips ----------------------------------------------------------------------------------

TEST(WeartRoundTrip, EveryClientCommandReadsBack) {
  using Kind = ClientCommand::Kind;
  EXPECT_EQ(commandOf(startFrame()).text, "TrackType1");
  EXPECT_EQ(commandOf(startFrame()).sdkType, "SdkLLCPP");
  EXPECT_EQ(commandOf(stopFrame()).kind, Kind::Stop);
  EXPECT_EQ(commandOf(startCalibrationFrame()).kind, Kind::StartCalibration);
  EXPECT_EQ(commandOf(stopCalibrationFrame()).kind, Kind::StopCalibration);
  const float values[] = {0.0f, 1e-6f, 0.1f, 0.25f, 0.5f, 0.8f, 1.0f / 3.0f, 0.999999f, 1.0f};
  auto written = [](float v) { return v >= 1e-6f ? v : 0.0f; };  // below 1e-6 is written 0
  for (const HandSide h : kHands) {
    for (const Point p : kPoints) {
      for (const float v : values) {
        ClientCommand c = commandOf(forceFrame(h, p, v));
        EXPECT_EQ(c.kind, Kind::Force);
        EXPECT_EQ(c.hand, h);
        EXPECT_EQ(c.point, p);
        EXPECT_EQ(c.value, v);  // the shortest spelling reads back bit for bit
        c = commandOf(temperatureFrame(h, p, v));
        EXPECT_EQ(c.kind, Kind::Temperature);
        EXPECT_EQ(c.value, v);
        EXPECT_EQ(c.hand, h);
        EXPECT_EQ(c.point, p);
        c = commandOf(textureFrame(h, p, static_cast<int>(v * 21.0f), v * 0.5f, v * 100.0f));
        EXPECT_EQ(c.kind, Kind::Texture);
        EXPECT_EQ(c.textureIndex, static_cast<int>(v * 21.0f));
        EXPECT_EQ(c.value, written(v * 0.5f));
        EXPECT_EQ(c.volume, written(v * 100.0f));
        EXPECT_EQ(c.point, p);
      }
      for (const auto& [frame, kind] : {std::pair{stopForceFrame(h, p), Kind::StopForce},
                                        std::pair{stopTemperatureFrame(h, p), Kind::StopTemperature},
                                        std::pair{stopTextureFrame(h, p), Kind::StopTexture}}) {
        const ClientCommand c = commandOf(frame);
        EXPECT_EQ(c.kind, kind);
        EXPECT_EQ(c.hand, h);
        EXPECT_EQ(c.point, p);
      }
    }
  }
  for (const char* type : {"MW_GET_STATUS", "DEVICES_GET_STATUS", "WA_GET_STATUS", "RAW_DATA_ON", "RAW_DATA_OFF"}) {
    for (const std::uint64_t ts : {std::uint64_t{0}, std::uint64_t{1717600000000}, ~std::uint64_t{0}}) {
      const std::string frame = requestFrame(type, ts);
      const ClientCommand c = commandOf(frame);
      EXPECT_EQ(c.kind, Kind::Request);
      EXPECT_EQ(c.text, type);
      EXPECT_EQ(c.timestampMs, ts);
    }
  }
  EXPECT_EQ(requestFrame("MW_GET_STATUS", 1717600000000), "{\"type\":\"MW_GET_STATUS\",\"ts\":1717600000000}~");
}

TEST(WeartRoundTrip, ClientFramesClampAndSpellNumbersPlainly) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  constexpr float kInf = std::numeric_limits<float>::infinity();
  const auto R = HandSide::Right;
  EXPECT_EQ(startFrame(), "StartFromClient:SdkLLCPP:2.0.0:TrackType1~");
  EXPECT_EQ(forceFrame(R, Point::Index, 0.8f), "force:0.8:0:0:RIGHT:INDEX~");
  EXPECT_EQ(forceFrame(HandSide::Left, Point::Palm, 1.0f), "force:1:0:0:LEFT:PALM~");
  EXPECT_EQ(forceFrame(R, Point::Index, 1.5f), "force:1:0:0:RIGHT:INDEX~");
  EXPECT_EQ(forceFrame(R, Point::Index, kInf), "force:1:0:0:RIGHT:INDEX~");
  EXPECT_EQ(forceFrame(R, Point::Index, -0.3f), "force:0:0:0:RIGHT:INDEX~");
  EXPECT_EQ(forceFrame(R, Point::Index, -0.0f), "force:0:0:0:RIGHT:INDEX~");
  EXPECT_EQ(forceFrame(R, Point::Index, kNaN), "force:0:0:0:RIGHT:INDEX~");
  EXPECT_EQ(forceFrame(R, Point::Index, 9e-7f), "force:0:0:0:RIGHT:INDEX~");  // never "9e-07"
  EXPECT_EQ(forceFrame(R, Point::Index, 1e-6f), "force:0.000001:0:0:RIGHT:INDEX~");
  EXPECT_EQ(temperatureFrame(R, Point::Thumb, 0.5f), "temperature:0.5:RIGHT:THUMB~");
  EXPECT_EQ(temperatureFrame(R, Point::Thumb, 2.0f), "temperature:1:RIGHT:THUMB~");
  EXPECT_EQ(temperatureFrame(R, Point::Thumb, kNaN), "temperature:0.5:RIGHT:THUMB~");  // neutral, not coldest
  EXPECT_EQ(stopForceFrame(HandSide::Left, Point::Thumb), "stopForce:LEFT:THUMB~");
  EXPECT_EQ(stopTemperatureFrame(R, Point::Annular), "stopTemperature:RIGHT:ANNULAR~");
  EXPECT_EQ(stopTextureFrame(R, Point::Pinky), "stopTexture:RIGHT:PINKY~");
  EXPECT_EQ(textureFrame(R, Point::Index, 9, 0.5f, 100.0f), "texture:9:0.5:0:0.5:100:RIGHT:INDEX~");
  EXPECT_EQ(textureFrame(R, Point::Index, 22, 0.9f, 150.0f), "texture:255:0.5:0:0.5:100:RIGHT:INDEX~");
  EXPECT_EQ(textureFrame(R, Point::Index, -1, kNaN, kNaN), "texture:255:0.5:0:0:0:RIGHT:INDEX~");
  EXPECT_EQ(textureFrame(R, Point::Index, 255, -1.0f, -5.0f), "texture:255:0.5:0:0:0:RIGHT:INDEX~");
  EXPECT_EQ(textureFrame(R, Point::Index, 0, 0.25f, 42.5f), "texture:0:0.5:0:0.25:42.5:RIGHT:INDEX~");

  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 20000; ++i) {
    const float v = i < 300 ? std::ldexp(1.0f, -i / 10) : unit(rng);  // also tiny values around 1e-6
    const std::string frame = forceFrame(R, Point::Middle, v);
    const std::string number = frame.substr(6, frame.find(':', 6) - 6);
    ASSERT_EQ(number.find_first_not_of("0123456789."), std::string::npos) << frame;
    const ClientCommand c = commandOf(frame);
    ASSERT_EQ(c.value, v >= 1e-6f ? v : 0.0f) << frame;
  }
}

// A C++ locale whose numbers use a decimal comma: std::to_chars and the parsers must not care.
struct CommaPunct : std::numpunct<char> {
  char do_decimal_point() const override { return ','; }
  char do_thousands_sep() const override { return '.'; }
  std::string do_grouping() const override { return "\3"; }
};

TEST(WeartRoundTrip, NumbersIgnoreTheGlobalCppLocale) {
  const std::locale previous = std::locale::global(std::locale(std::locale::classic(), new CommaPunct));
  const std::string force = forceFrame(HandSide::Right, Point::Index, 1234.5f / 2000.0f);
  const std::string g1 = trackingG1Frame({});
  HandTracking hand;
  hand.closure.fill(0.5f);
  const std::string g2 = trackingG2Frame(hand, 1234567);
  const auto back = parseMiddlewareFrame(g2);
  const auto forceBack = parseClientFrame(force);
  std::locale::global(previous);
  EXPECT_EQ(force, "force:0.61725:0:0:RIGHT:INDEX~");
  EXPECT_NE(g2.find(R"("ts":1234567,)"), std::string::npos) << g2;
  EXPECT_NE(g2.find(R"("closure":0.5,)"), std::string::npos) << g2;
  ASSERT_TRUE(back.message);
  EXPECT_EQ(std::get<Tracking>(*back.message).hands.at(0).closure[0], 0.5f);
  ASSERT_TRUE(forceBack.command);
  EXPECT_EQ(forceBack.command->value, 1234.5f / 2000.0f);
}

TEST(WeartRoundTrip, NumbersIgnoreTheLocale) {
  const char* found = nullptr;
  for (const char* name : {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "it_IT.UTF-8", "ru_RU.UTF-8"})
    if (std::setlocale(LC_ALL, name)) {
      found = name;
      break;
    }
  if (!found) GTEST_SKIP() << "no locale with a decimal comma installed";
  std::locale previous;
  try {
    previous = std::locale::global(std::locale(found));
  } catch (const std::exception&) {
  }
  const std::string force = forceFrame(HandSide::Right, Point::Index, 0.8f);
  const std::string texture = textureFrame(HandSide::Right, Point::Index, 1, 0.25f, 42.5f);
  HandTracking hand;
  hand.closure.fill(0.5f);
  const std::string g2 = trackingG2Frame(hand, 1);
  const bool g2Reads = parseMiddlewareFrame(g2).message.has_value();
  const bool forceReads = parseClientFrame("force:0.8:0:0:RIGHT:INDEX").command.has_value();
  std::locale::global(previous);
  std::setlocale(LC_ALL, "C");
  EXPECT_EQ(force, "force:0.8:0:0:RIGHT:INDEX~") << found;
  EXPECT_EQ(texture, "texture:1:0.5:0:0.25:42.5:RIGHT:INDEX~");
  EXPECT_NE(g2.find("\"closure\":0.5"), std::string::npos) << g2;
  EXPECT_TRUE(g2Reads);
  EXPECT_TRUE(forceReads);
}

MiddlewareStatus sampleStatus(bool pro) {
  MiddlewareStatus s;
  s.pro = pro;
  s.status = "RUNNING";
  s.version = "2.0.1";
  s.statusCode = 101;
  s.errorDesc = "connect at least one thimble";
  s.warningCode = 102;
  s.warningDesc = "signal weak";
  s.actuationsEnabled = false;
  s.connectedDevices = {{"AA:BB:CC:DD:EE:01", HandSide::Right}, {"AA:BB:CC:DD:EE:02", HandSide::Left}};
  if (pro) {
    s.connectionType = "WIFI";
    s.autoconnection = true;
    s.deviceSelection = "VirtualDevices";
    s.trackingPlayback = true;
    s.rawDataLog = true;
    s.sensorOnMask = true;
  }
  return s;
}

void expectSameStatus(const MiddlewareStatus& a, const MiddlewareStatus& b) {
  EXPECT_EQ(a.pro, b.pro);
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.version, b.version);
  EXPECT_EQ(a.statusCode, b.statusCode);
  EXPECT_EQ(a.errorDesc, b.errorDesc);
  EXPECT_EQ(a.warningCode, b.warningCode);
  EXPECT_EQ(a.warningDesc, b.warningDesc);
  EXPECT_EQ(a.actuationsEnabled, b.actuationsEnabled);
  ASSERT_EQ(a.connectedDevices.size(), b.connectedDevices.size());
  for (std::size_t i = 0; i < a.connectedDevices.size(); ++i) {
    EXPECT_EQ(a.connectedDevices[i].macAddress, b.connectedDevices[i].macAddress);
    EXPECT_EQ(a.connectedDevices[i].hand, b.connectedDevices[i].hand);
  }
  EXPECT_EQ(a.connectionType, b.connectionType);
  EXPECT_EQ(a.autoconnection, b.autoconnection);
  EXPECT_EQ(a.deviceSelection, b.deviceSelection);
  EXPECT_EQ(a.trackingPlayback, b.trackingPlayback);
  EXPECT_EQ(a.rawDataLog, b.rawDataLog);
  EXPECT_EQ(a.sensorOnMask, b.sensorOnMask);
}

TEST(WeartRoundTrip, StatusFramesReadBack) {
  for (const bool pro : {false, true}) {
    const MiddlewareStatus sent = sampleStatus(pro);
    const std::string frame = statusFrame(sent, 1717600000123);
    EXPECT_EQ(frame.rfind(pro ? R"({"type":"WA_STATUS","ts":1717600000123,"data":{"status":"RUNNING",)"
                              : R"({"type":"MW_STATUS","ts":1717600000123,"data":{"status":"RUNNING",)",
                          0),
              0u)
        << frame;
    const auto p = parseMiddlewareFrame(frame);
    ASSERT_EQ(p.error, "");
    EXPECT_EQ(p.timestampMs, 1717600000123u);
    expectSameStatus(std::get<MiddlewareStatus>(*p.message), sent);
  }
}

TEST(WeartRoundTrip, StatusFramesMatchTheNotesExamplesByteForByte) {
  MiddlewareStatus mw;
  mw.status = "RUNNING";
  mw.version = "1.4.0";
  mw.connectedDevices = {{"AA:BB:CC:DD:EE:01", HandSide::Right}};
  EXPECT_EQ(statusFrame(mw, 1717600000123), kMwStatusExample);
  EXPECT_EQ(
      statusFrame(MiddlewareStatus{}, 0),
      R"({"type":"MW_STATUS","ts":0,"data":{"status":"","version":"","statusCode":0,"errorDesc":"","warningCode":0,"warningDesc":"","actuationsEnabled":true,"connectedDevices":[]}}~)");

  MiddlewareStatus wa;
  wa.pro = true;
  wa.status = "IDLE";
  wa.version = "2.0.0";
  wa.connectionType = "BLE";
  wa.autoconnection = true;
  wa.connectedDevices = {{"AA:BB:CC:DD:EE:02", HandSide::Left}};
  EXPECT_EQ(statusFrame(wa, 1717600000123), kWaStatusExample);  // deviceSelection "" is written PhysicalDevices

  DevicesStatus devices;
  DevicesStatus::Device glove;
  glove.macAddress = "AA:BB:CC:DD:EE:01";
  glove.batteryLevel = 85;
  for (const Point p : {Point::Thumb, Point::Index, Point::Middle}) glove.nodes.push_back({p, true, 0, ""});
  devices.devices.push_back(glove);
  EXPECT_EQ(devicesFrame(devices, 1717600000124), kDevicesStatusExample);

  DevicesStatus pro;
  pro.pro = true;
  DevicesStatus::Device master;
  master.macAddress = "AA:BB:CC:DD:EE:02";
  master.hand = HandSide::Left;
  master.batteryLevel = 90;
  master.signalStrength = -60.5;
  master.sensorsCalibDate = "2026-02-03T09:03:03Z";
  master.connection.bluetoothOn = master.connection.bluetoothConnected = true;
  for (const Point p : {Point::Thumb, Point::Palm}) master.nodes.push_back({p, true, 0, ""});
  pro.devices.push_back(master);
  EXPECT_EQ(devicesFrame(pro, 1717600000125), kProStatusExample);
}

TEST(WeartRoundTrip, DevicesFramesReadBack) {
  for (const bool pro : {false, true}) {
    DevicesStatus sent;
    sent.pro = pro;
    for (const HandSide h : kHands) {
      DevicesStatus::Device d;
      d.macAddress = h == HandSide::Left ? "AA:BB:CC:DD:EE:02" : "AA:BB:CC:DD:EE:01";
      d.hand = h;
      d.batteryLevel = 42;
      d.charging = h == HandSide::Left;
      d.signalStrength = h == HandSide::Left ? -71.25 : -40.0;
      d.sensorsCalibDate = "2026-02-03T09:03:03Z";
      d.connection.wifiOn = d.connection.wifiConnected = h == HandSide::Left;
      d.connection.usbConnected = h == HandSide::Right;
      for (const Point p : kPoints) d.nodes.push_back({p, p != Point::Pinky, pro ? 0 : 7, pro ? "" : "thimble error"});
      sent.devices.push_back(d);
    }
    const std::string frame = devicesFrame(sent, 99);
    const auto p = parseMiddlewareFrame(frame);
    ASSERT_EQ(p.error, "") << frame;
    EXPECT_EQ(p.timestampMs, 99u);
    const auto& got = std::get<DevicesStatus>(*p.message);
    EXPECT_EQ(got.pro, pro);
    ASSERT_EQ(got.devices.size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) {
      EXPECT_EQ(got.devices[i].macAddress, sent.devices[i].macAddress);
      EXPECT_EQ(got.devices[i].hand, sent.devices[i].hand);
      EXPECT_EQ(got.devices[i].batteryLevel, 42);
      EXPECT_EQ(got.devices[i].charging, sent.devices[i].charging);
      // The Pro-only fields travel in WEART_TD_PRO_STATUS only.
      const DevicesStatus::Device expected = pro ? sent.devices[i] : DevicesStatus::Device{};
      EXPECT_EQ(got.devices[i].signalStrength, expected.signalStrength);
      EXPECT_EQ(got.devices[i].sensorsCalibDate, expected.sensorsCalibDate);
      EXPECT_EQ(got.devices[i].connection.wifiConnected, expected.connection.wifiConnected);
      EXPECT_EQ(got.devices[i].connection.usbConnected, expected.connection.usbConnected);
      EXPECT_EQ(got.devices[i].connection.bluetoothOn, expected.connection.bluetoothOn);
      ASSERT_EQ(got.devices[i].nodes.size(), static_cast<std::size_t>(kPointCount));
      for (std::size_t n = 0; n < got.devices[i].nodes.size(); ++n) {
        const auto& a = got.devices[i].nodes[n];
        const auto& b = sent.devices[i].nodes[n];
        EXPECT_EQ(a.point, b.point);
        EXPECT_EQ(a.connected, b.connected);
        EXPECT_EQ(a.statusCode, b.statusCode);
        EXPECT_EQ(a.errorDesc, b.errorDesc);
      }
    }
  }
}

TEST(WeartRoundTrip, G1TrackingRoundsToBytes) {
  HandTracking right;
  right.hand = HandSide::Right;
  right.closure = {0.5f, 200.0f / 255.0f, 1.5f, 0.3f, 0.3f, 0.3f};  // thumb, index, middle (clamped), ...
  right.thumbAbduction = 110.0f / 255.0f;
  EXPECT_EQ(trackingG1Frame({right}), "Tracking:TrackType1:200:128:110:255:0:0:0:0~");
  HandTracking left;
  left.hand = HandSide::Left;
  left.closure.fill(std::numeric_limits<float>::quiet_NaN());
  left.closure[idx(Point::Index)] = 1.0f / 255.0f;
  left.thumbAbduction = -1.0f;
  const std::string frame = trackingG1Frame({left, right});
  EXPECT_EQ(frame, "Tracking:TrackType1:200:128:110:255:1:0:0:0~");
  const Tracking t = messageOf<Tracking>(frame);
  ASSERT_EQ(t.hands.size(), 2u);
  EXPECT_FLOAT_EQ(t.hands[0].closure[idx(Point::Index)], 200.0f / 255.0f);
  EXPECT_FLOAT_EQ(t.hands[0].closure[idx(Point::Thumb)], 128.0f / 255.0f);
  EXPECT_FLOAT_EQ(t.hands[0].closure[idx(Point::Middle)], 1.0f);
  EXPECT_FLOAT_EQ(t.hands[0].thumbAbduction, 110.0f / 255.0f);
  EXPECT_FLOAT_EQ(t.hands[1].closure[idx(Point::Index)], 1.0f / 255.0f);
  EXPECT_EQ(trackingG1Frame({}), "Tracking:TrackType1:0:0:0:0:0:0:0:0~");
  for (int b = 0; b <= 255; ++b) {  // every byte survives parse -> format
    const std::string f = "Tracking:TrackType1:" + std::to_string(b) + ":0:" + std::to_string(255 - b) +
                          ":0:0:0:0:" + std::to_string(b) + "~";
    ASSERT_EQ(trackingG1Frame(messageOf<Tracking>(f).hands), f);
  }
}

TEST(WeartRoundTrip, G1DefaultTrackingCarriesThumbIndexMiddlePalm) {
  HandTracking right;
  right.hand = HandSide::Right;
  right.closure = {10.0f / 255.0f, 20.0f / 255.0f, 30.0f / 255.0f, 0.9f, 0.9f, 40.0f / 255.0f};
  right.thumbAbduction = 0.9f;  // not carried
  HandTracking left = right;
  left.hand = HandSide::Left;
  left.closure = {50.0f / 255.0f, 60.0f / 255.0f, 70.0f / 255.0f, 0.9f, 0.9f, 80.0f / 255.0f};
  const std::string frame = trackingG1Frame({left, right}, TrackType::Default);
  EXPECT_EQ(frame, "Tracking:10:20:30:40:50:60:70:80~");  // §7.3.1's example
  const Tracking t = messageOf<Tracking>(frame);
  ASSERT_EQ(t.hands.size(), 2u);
  for (std::size_t h = 0; h < 2; ++h) {
    const HandTracking& sent = h == 0 ? right : left;
    for (const Point p : {Point::Thumb, Point::Index, Point::Middle, Point::Palm})
      EXPECT_FLOAT_EQ(t.hands[h].closure[idx(p)], sent.closure[idx(p)]);
    EXPECT_TRUE(std::isnan(t.hands[h].thumbAbduction));
  }
  EXPECT_EQ(trackingG1Frame({}, TrackType::Default), "Tracking:0:0:0:0:0:0:0:0~");
}

TEST(WeartRoundTrip, RawDataFramesReadBack) {
  std::vector<RawSample> samples;
  for (const Point p : kPoints)
    samples.push_back({p, {0.01f, -0.98f, 0.05f}, {0.3f, -1.2f, 0.0f}, p == Point::Palm ? 0 : 42});
  const std::string g1 = rawDataFrame(HandSide::Right, {samples[1], samples[5]}, false, 1717600000500);
  // §7.9's example, byte for byte.
  EXPECT_EQ(
      g1,
      R"({"type":"RAW_DATA","ts":1717600000500,"data":{"handSide":"RIGHT","index":{"accelerometer":{"x":0.01,"y":-0.98,"z":0.05},"gyroscope":{"x":0.3,"y":-1.2,"z":0.0},"timeOfFlight":{"distance":42}},"palm":{"accelerometer":{"x":0.01,"y":-0.98,"z":0.05},"gyroscope":{"x":0.3,"y":-1.2,"z":0.0},"timeOfFlight":{"distance":0}}}}~)");
  const std::string pro = rawDataFrame(HandSide::Left, samples, true, 7);
  EXPECT_EQ(pro.find("timeOfFlight"), std::string::npos) << pro;  // §7.10: the Pro has none
  const auto got = messageOf<RawData>(pro);
  EXPECT_EQ(got.type, "RAW_DATA_TD_PRO");
  EXPECT_EQ(got.hand, HandSide::Left);
  EXPECT_EQ(got.points, std::vector<Point>(std::begin(kPoints), std::end(kPoints)));
}

TEST(WeartRoundTrip, ProTrackingReadsBack) {
  HandTracking sent;
  sent.hand = HandSide::Left;
  sent.closure = {0.31f, 0.72f, 0.65f, 0.6f, 0.55f, 0.0f};
  sent.thumbAbduction = 0.44f;
  std::string frame = trackingG2Frame(sent, 1717600000456);
  EXPECT_NE(frame.find(R"("thumb":{"closure":0.31,"abduction":0.44})"), std::string::npos) << frame;
  EXPECT_EQ(frame.find("wrist"), std::string::npos);
  auto p = parseMiddlewareFrame(frame);
  ASSERT_EQ(p.error, "");
  EXPECT_EQ(p.timestampMs, 1717600000456u);
  HandTracking got = std::get<Tracking>(*p.message).hands.at(0);
  EXPECT_EQ(got.hand, HandSide::Left);
  EXPECT_EQ(got.closure, sent.closure);
  EXPECT_EQ(got.thumbAbduction, sent.thumbAbduction);
  EXPECT_FALSE(got.wristQuaternion);

  sent.wristQuaternion = std::array<float, 4>{0.0f, 0.6f, 0.0f, 0.8f};
  sent.closure[idx(Point::Pinky)] = std::numeric_limits<float>::quiet_NaN();  // sent as 0
  sent.closure[idx(Point::Palm)] = 3.0f;                                      // clamped to 1
  frame = trackingG2Frame(sent, 5);
  got = std::get<Tracking>(*parseMiddlewareFrame(frame).message).hands.at(0);
  EXPECT_EQ(got.closure[idx(Point::Pinky)], 0.0f);
  EXPECT_EQ(got.closure[idx(Point::Palm)], 1.0f);
  ASSERT_TRUE(got.wristQuaternion);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR((*got.wristQuaternion)[i], (*sent.wristQuaternion)[i], 1e-6f);
}

TEST(WeartRoundTrip, CalibrationFramesReadBack) {
  for (const HandSide h : kHands) {
    for (int s = 0; s <= 2; ++s) {
      const auto got = messageOf<CalibrationStatus>(calibrationStatusFrame(h, s));
      EXPECT_EQ(got.hand, h);
      EXPECT_EQ(got.status, s);
    }
    for (const bool ok : {true, false}) {
      const auto got = messageOf<CalibrationResult>(calibrationResultFrame(h, ok));
      EXPECT_EQ(got.hand, h);
      EXPECT_EQ(got.success, ok);
    }
  }
  EXPECT_EQ(calibrationResultFrame(HandSide::Right, true), "CalibrationResult:1:0~");
  EXPECT_EQ(calibrationStatusFrame(HandSide::Left, 1), "CalibrationStatus:0:1~");
}

TEST(WeartRoundTrip, AnyStringStaysInsideItsFrame) {
  MiddlewareStatus s;
  s.errorDesc = std::string("tilde ~ colon : quote \" backslash \\ newline \n nul ") + '\0' + " utf8 \xc3\xa9 bad \xff";
  s.version = "~~~";
  s.connectedDevices = {{"~:~", HandSide::Left}};
  const std::string frame = statusFrame(s, 3);
  EXPECT_EQ(frame.find('~'), frame.size() - 1) << frame;  // only the terminator
  EXPECT_TRUE(isAscii(frame)) << frame;
  const auto frames = splitAll(frame);
  ASSERT_EQ(frames.size(), 1u);
  const auto got = messageOf<MiddlewareStatus>(frames[0]);
  EXPECT_EQ(got.version, "~~~");
  EXPECT_EQ(got.connectedDevices.at(0).macAddress, "~:~");
  // Invalid UTF-8 is replaced (U+FFFD), everything else survives.
  EXPECT_EQ(got.errorDesc, std::string("tilde ~ colon : quote \" backslash \\ newline \n nul ") + '\0' +
                               " utf8 \xc3\xa9 bad \xef\xbf\xbd");
  EXPECT_TRUE(isAscii(requestFrame("A~\xff", 1)));
  EXPECT_EQ(requestFrame("A~B", 1).find('~'), requestFrame("A~B", 1).size() - 1);
}

// --- Strictness --------------------------------------------------------------------------------------

TEST(WeartParse, G1TrackingTakesIntegers0To255Only) {
  for (const char* value : {"256", "-1", "12abc", "1e999", "1e2", "nan", "inf", "1.5", "0.0", " 1", "1 ", "+1", "",
                            "0x10", "99999999999", "\xd9\xa1"}) {
    const std::string frame = "Tracking:TrackType1:" + std::string(value) + ":0:0:0:0:0:0:0";
    EXPECT_NE(middlewareError(frame), "") << value;
    EXPECT_NE(middlewareError("Tracking:0:0:0:" + std::string(value) + ":0:0:0:0"), "") << value;
  }
  middlewareError("Tracking:TrackType1:1:2:3:4:5:6:7");
  middlewareError("Tracking:TrackType1:1:2:3:4:5:6:7:8:9");
  middlewareError("Tracking:1:2:3:4:5:6:7");
  middlewareError("Tracking:1:2:3:4:5:6:7:8:9");
  middlewareError("Tracking:TrackType0:1:2:3:4:5:6:7:8");
  middlewareError("Tracking");
  middlewareError(std::string("Tracking") + std::string(200, ':'));
}

TEST(WeartParse, CalibrationCodesAreStrict) {
  for (const char* frame :
       {"CalibrationStatus:2:1", "CalibrationStatus:1:3", "CalibrationStatus:RIGHT:1", "CalibrationStatus:1",
        "CalibrationStatus:1:1:1", "CalibrationStatus:-0:1", "CalibrationResult:1:2", "CalibrationResult:1:-1",
        "CalibrationResult:1:0.0", "CalibrationResult:one:0", "exit:now", "disconnect:1"})
    middlewareError(frame);
}

TEST(WeartParse, ProTrackingValuesAreClampedButMustBeNumbers) {
  const std::string head = R"({"type":"TRACKING_BENDING_G2","ts":1,"data":{"handSide":"LEFT",)";
  const std::string rest =
      R"("index":{"closure":0.7},"middle":{"closure":0.6},"annular":{"closure":0.6},"pinky":{"closure":0.5},"palm":{"closure":0}})";
  const HandTracking h =
      messageOf<Tracking>(head + R"("thumb":{"closure":1.2,"abduction":-0.1},)" + rest + "}").hands.at(0);
  EXPECT_EQ(h.closure[idx(Point::Thumb)], 1.0f);
  EXPECT_EQ(h.thumbAbduction, 0.0f);
  EXPECT_FLOAT_EQ(h.closure[idx(Point::Pinky)], 0.5f);
  EXPECT_EQ(h.closure[idx(Point::Palm)], 0.0f);  // an integer is a number too
  for (const char* thumb :
       {R"("thumb":{"closure":"0.3","abduction":0.1},)", R"("thumb":{"closure":null,"abduction":0.1},)",
        R"("thumb":{"closure":true,"abduction":0.1},)", R"("thumb":{"closure":0.3},)", R"("thumb":{"abduction":0.1},)",
        R"("thumb":[0.3,0.1],)", R"("thumb":{"closure":1e999,"abduction":0},)", R"()"})
    middlewareError(head + thumb + rest + "}");
  const std::string full = head + R"("thumb":{"closure":0.3,"abduction":0.1},)" + rest;
  const std::string withWrist = full.substr(0, full.size() - 1) + R"(,"wrist":{"quaternion":)";
  const auto q = messageOf<Tracking>(withWrist + R"({"x":0,"y":0,"z":0,"w":2}}}})").hands.at(0).wristQuaternion;
  ASSERT_TRUE(q);
  EXPECT_EQ(*q, (std::array<float, 4>{0.0f, 0.0f, 0.0f, 1.0f}));  // normalised
  const auto big =
      messageOf<Tracking>(withWrist + R"({"x":1e300,"y":1e300,"z":0,"w":0}}}})").hands.at(0).wristQuaternion;
  ASSERT_TRUE(big);
  EXPECT_FLOAT_EQ((*big)[0], std::sqrt(0.5f));
  for (const char* quat : {R"({"x":0,"y":0,"z":0,"w":0}}}})", R"({"x":0,"y":0,"z":0}}}})",
                           R"({"x":"0","y":0,"z":0,"w":1}}}})", R"([0,0,0,1]}}})"})
    middlewareError(withWrist + quat);
  middlewareError(full.substr(0, full.size() - 1) + R"(,"wrist":{}}})");
  middlewareError(full.substr(0, full.size() - 1) + R"(,"wrist":1}})");
}

TEST(WeartParse, StatusFieldsMustHaveTheirTypes) {
  for (const char* data :
       {R"({"status":"running"})", R"({"status":5})", R"({"statusCode":"0"})", R"({"statusCode":0.5})",
        R"({"statusCode":3000000000})", R"({"actuationsEnabled":"true"})", R"({"actuationsEnabled":1})",
        R"({"version":1.4})", R"({"connectedDevices":{}})", R"({"connectedDevices":[{"handSide":"LEFT"}]})",
        R"({"connectedDevices":[{"macAddress":"AA","handSide":"left"}]})",
        R"({"connectedDevices":[{"macAddress":"AA","handSide":0}]})", R"({"connectedDevices":[1]})",
        R"({"connectionType":"ble"})", R"({"sensorOnMask":null})"})
    middlewareError(std::string(R"({"type":"WA_STATUS","ts":1,"data":)") + data + "}");
  // Missing keys take their defaults (the C++ SDK's parser does the same, §7.5).
  const auto s = messageOf<MiddlewareStatus>(R"({"type":"MW_STATUS","ts":1})");
  EXPECT_EQ(s.status, "");
  EXPECT_TRUE(s.actuationsEnabled);
  EXPECT_EQ(messageOf<MiddlewareStatus>(R"({"type":"MW_STATUS","ts":1,"data":{"statusCode":-2}})").statusCode, -2);
  for (const char* data : {R"({})", R"({"devices":{}})", R"({"devices":[{"handSide":"LEFT"}]})",
                           R"({"devices":[{"macAddress":"AA","handSide":"LEFT","thimbles":[{"id":"thumb"}]}]})",
                           R"({"devices":[{"macAddress":"AA","handSide":"LEFT","thimbles":[{"connected":true}]}]})",
                           R"({"devices":[{"macAddress":"AA","handSide":"LEFT","batteryLevel":85.5}]})",
                           R"({"devices":[{"macAddress":"AA","handSide":"LEFT","thimbles":{}}]})"})
    middlewareError(std::string(R"({"type":"DEVICES_STATUS","ts":1,"data":)") + data + "}");
  for (const char* device :
       {R"("signalStrength":"-60")", R"("signalStrength":true)", R"("sensorsCalibDate":20260203)",
        R"("master":{"connection":[]})", R"("master":{"connection":{"bluetoothConnected":"true"}})"})
    middlewareError(
        std::string(
            R"({"type":"WEART_TD_PRO_STATUS","ts":1,"data":{"devices":[{"macAddress":"AA","handSide":"LEFT",)") +
        device + "}]}}");
  for (const char* sensor : {R"("thumb":1)", R"("index":[])", R"("palm":null)"})
    middlewareError(std::string(R"({"type":"RAW_DATA","ts":1,"data":{"handSide":"LEFT",)") + sensor + "}}");
}

TEST(WeartParse, JsonEnvelopeNeedsAnObjectWithStringTypeAndIntegerTs) {
  for (const char* frame : {R"({"type":"MW_STATUS"})",
                            R"({"type":"MW_STATUS","ts":"1"})",
                            R"({"type":"MW_STATUS","ts":1.0})",
                            R"({"type":"MW_STATUS","ts":-1})",
                            R"({"type":"MW_STATUS","ts":1e3})",
                            R"({"type":"MW_STATUS","ts":18446744073709551616})",
                            R"({"type":"MW_STATUS","ts":true})",
                            R"({"ts":1})",
                            R"({"type":7,"ts":1})",
                            R"({"type":"","ts":1})",
                            R"({"type":"A B","ts":1})",
                            R"({"type":"MW_STATUS","ts":1,"data":[]})",
                            R"({"type":"MW_STATUS","ts":1,"data":"x"})",
                            R"([{"type":"MW_STATUS","ts":1}])",
                            R"({"type":"MW_STATUS","ts":1)",
                            R"({"type":"MW_STATUS","ts":1}})",
                            R"({"type":"MW_STATUS","ts":1} {})",
                            R"({'type':'MW_STATUS','ts':1})",
                            "{}",
                            "{",
                            "[]",
                            "\"MW_STATUS\"",
                            "42"}) {
    middlewareError(frame);
    clientError(frame);
  }
  const auto p = parseMiddlewareFrame(R"({"type":"SOMETHING_NEW","ts":18446744073709551615,"data":[1]})");
  ASSERT_TRUE(p.message);
  EXPECT_EQ(std::get<Unknown>(*p.message).id, "SOMETHING_NEW");
  EXPECT_EQ(p.timestampMs, 18446744073709551615u);
  EXPECT_EQ(messageOf<Unknown>("SensorsData:0:1:0.1:0.2:0.3:1:2:3:42").id, "SensorsData");
  EXPECT_EQ(messageOf<Unknown>("force:0.5:0:0:RIGHT:INDEX").id, "force");  // a client frame, not ours
}

TEST(WeartParse, ClientFramesAreStrict) {
  for (const char* frame : {"force:0.5:0:RIGHT:INDEX",
                            "force:0.5:0:0:RIGHT:INDEX:1",
                            "force:1.5:0:0:RIGHT:INDEX",
                            "force:-0.1:0:0:RIGHT:INDEX",
                            "force:nan:0:0:RIGHT:INDEX",
                            "force:inf:0:0:RIGHT:INDEX",
                            "force:1e999:0:0:RIGHT:INDEX",
                            "force:0,5:0:0:RIGHT:INDEX",
                            "force:0x1p-1:0:0:RIGHT:INDEX",
                            "force:12abc:0:0:RIGHT:INDEX",
                            "force:+0.5:0:0:RIGHT:INDEX",
                            "force:.:0:0:RIGHT:INDEX",
                            "force:1e:0:0:RIGHT:INDEX",
                            "force: 0.5:0:0:RIGHT:INDEX",
                            "force:0.5:2:0:RIGHT:INDEX",
                            "force:0.5:0:0:right:INDEX",
                            "force:0.5:0:0:RIGHT:index",
                            "force:0.5:0:0:RIGHT:RING",
                            "force:0.5:0:0:INDEX:RIGHT",
                            "temperature:0.5:RIGHT",
                            "temperature::RIGHT:INDEX",
                            "temperature:1.0001:RIGHT:INDEX",
                            "texture:22:0.5:0:0.5:100:RIGHT:INDEX",
                            "texture:-1:0.5:0:0.5:100:RIGHT:INDEX",
                            "texture:9.0:0.5:0:0.5:100:RIGHT:INDEX",
                            "texture:9:0.5:0:0.6:100:RIGHT:INDEX",
                            "texture:9:0.5:0:0.5:101:RIGHT:INDEX",
                            "texture:9:0.5:0:0.5:RIGHT:INDEX",
                            "stopForce:LEFT",
                            "stopForce:LEFT:THUMB:1",
                            "StopFromClient:now",
                            "StartCalibration:1",
                            "StartFromClient:SdkLLCPP:2.0.0",
                            "StartFromClient:SdkLLCPP::TrackType1",
                            "StartFromClient:a:b:c:d",
                            "Force:0.5:0:0:RIGHT:INDEX",
                            "vibrate:1",
                            "exit",
                            "Tracking:TrackType1:0:0:0:0:0:0:0:0",
                            R"({"type":"MW_GET_STATUS"})",
                            R"({"type":"MW_GET_STATUS","ts":"1"})",
                            R"({"type":"RAW_DATA_ON","ts":1,"data":"x"})",
                            R"({"type":"MW_STATUS","ts":1})",
                            R"({"type":"mw_get_status","ts":1})"})
    clientError(frame);
  EXPECT_FLOAT_EQ(commandOf("force:1e-05:0.0:0.0:LEFT:PINKY").value, 1e-5f);  // Python's str() of a small float
  EXPECT_EQ(commandOf("force:-0:0:0:LEFT:PINKY").value, 0.0f);
  EXPECT_EQ(commandOf("texture:255:0.5:0:0:0:LEFT:PALM").textureIndex, 255);
}

TEST(WeartParse, HostileBytesAndSizesAreErrors) {
  middlewareError("");
  middlewareError(" \r\n ");
  middlewareError("~");
  middlewareError("exit~exit");
  middlewareError(std::string("exit\0", 5));
  middlewareError(std::string("CalibrationStatus:1:\0", 21) + "1");
  middlewareError("exit\x7f");
  middlewareError("exit\xff");
  middlewareError(
      "\xef\xbb\xbf"
      "exit");  // a UTF-8 byte-order mark
  middlewareError("Tracking:TrackType1:2\xc3\xa9:0:0:0:0:0:0:0");
  // Size: a huge frame is refused before it is looked at; the limit itself is fine.
  const std::string pad = R"({"type":"MW_STATUS","ts":1,"data":{"errorDesc":")";
  const std::string end = R"("}})";
  EXPECT_EQ(messageOf<MiddlewareStatus>(pad + std::string(kMaxParsedFrame - pad.size() - end.size(), 'x') + end)
                .errorDesc.size(),
            kMaxParsedFrame - pad.size() - end.size());
  EXPECT_NE(middlewareError(pad + std::string(kMaxParsedFrame, 'x') + end).find("limit"), std::string::npos);
  clientError(std::string(10 * 1000 * 1000, 'x'));
  middlewareError(std::string(10 * 1000 * 1000, '['));
  // Depth: kMaxJsonDepth levels parse, one more does not, whatever the brackets.
  auto nested = [](int depth, bool objects) {
    std::string s = R"({"type":"NEW","ts":1,"x":)";
    for (int i = 1; i < depth; ++i) s += objects ? R"({"a":)" : "[";  // the frame's object is level 1
    s += "1";
    for (int i = 1; i < depth; ++i) s += objects ? "}" : "]";
    return s + "}";
  };
  EXPECT_EQ(messageOf<Unknown>(nested(kMaxJsonDepth, false)).id, "NEW");
  EXPECT_EQ(messageOf<Unknown>(nested(kMaxJsonDepth, true)).id, "NEW");
  EXPECT_NE(middlewareError(nested(kMaxJsonDepth + 1, false)).find("deeper"), std::string::npos);
  EXPECT_NE(clientError(nested(kMaxJsonDepth + 1, true)).find("deeper"), std::string::npos);
  EXPECT_EQ(messageOf<Unknown>(R"({"type":"NEW","ts":1,"x":"[[[[[[[[[[[[[[[[[[[[[[[[[[\"[[["})").id, "NEW");
}

// --- The malformed-frame corpus ------------------------------------------------------------------------

using testing::readBytes;

bool startsWith(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

TEST(WeartCorpus, EveryFileParsesAsItsNameSays) {
  const std::filesystem::path dir = std::filesystem::path(VRDEFORM_TEST_DATA_DIR) / "fuzz_corpus" / "weart";
  ASSERT_TRUE(std::filesystem::is_directory(dir)) << dir;
  std::map<std::string, int> counts;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    const std::string frame = readBytes(entry.path());
    SCOPED_TRACE(name);
    const ParsedMiddleware mw = parseMiddlewareFrame(frame);
    const ParsedClient client = parseClientFrame(frame);
    EXPECT_NE(mw.message.has_value(), !mw.error.empty()) << "a message or an error, never both or neither";
    EXPECT_NE(client.command.has_value(), !client.error.empty());
    const bool mwUnknown = mw.message && std::holds_alternative<Unknown>(*mw.message);
    if (startsWith(name, "ok_mw_")) {
      EXPECT_TRUE(mw.message && !mwUnknown) << mw.error;
      EXPECT_FALSE(client.command);
      ++counts["ok_mw"];
    } else if (startsWith(name, "ok_client_")) {
      EXPECT_TRUE(client.command) << client.error;
      EXPECT_TRUE(!mw.message || mwUnknown);
      ++counts["ok_client"];
    } else if (startsWith(name, "unknown_")) {
      EXPECT_TRUE(mwUnknown) << mw.error;
      EXPECT_FALSE(client.command);
      ++counts["unknown"];
    } else if (startsWith(name, "bad_client_")) {
      EXPECT_FALSE(client.command);
      EXPECT_TRUE(!mw.message || mwUnknown);
      ++counts["bad_client"];
    } else if (startsWith(name, "bad_")) {
      EXPECT_FALSE(mw.message);
      EXPECT_FALSE(client.command);
      ++counts["bad"];
    } else {
      ADD_FAILURE() << "a corpus file name must start with ok_mw_, ok_client_, unknown_, bad_client_ or bad_";
    }
    // Through the splitter, byte by byte, then a terminator: the same verdicts (frames over the
    // splitter's cap never come out).
    FrameSplitter splitter(4096);
    std::vector<std::string> frames;
    for (const char c : frame) splitter.feed(std::string_view(&c, 1), frames);
    EXPECT_LE(splitter.buffered(), 4096u);
    splitter.feed("~", frames);
    if (frame.find('~') == std::string::npos) {
      EXPECT_LE(frames.size(), 1u);
      for (const auto& f : frames) {
        EXPECT_EQ(parseMiddlewareFrame(f).message.has_value(), mw.message.has_value());
        EXPECT_EQ(parseClientFrame(f).command.has_value(), client.command.has_value());
      }
    }
  }
  for (const char* kind : {"ok_mw", "ok_client", "unknown", "bad_client", "bad"}) {
    EXPECT_GE(counts[kind], 4) << kind;
    vrd::testing::record(std::string("corpus_") + kind, counts[kind]);
  }
}

TEST(WeartCorpus, MutatedFramesGiveAMessageOrAnError) {
  const std::filesystem::path dir = std::filesystem::path(VRDEFORM_TEST_DATA_DIR) / "fuzz_corpus" / "weart";
  std::mt19937 rng(3);
  int accepted = 0, rejected = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (!startsWith(entry.path().filename().string(), "ok_")) continue;
    const std::string original = readBytes(entry.path());
    for (int i = 0; i < 500; ++i) {
      std::string frame = original;
      for (int edits = 1 + static_cast<int>(rng() % 4); edits > 0; --edits)
        frame = vrd::testing::mutate(frame, rng, ":~{}[]\",.-0123456789eE \\");
      const ParsedMiddleware mw = parseMiddlewareFrame(frame);
      const ParsedClient client = parseClientFrame(frame);
      ASSERT_NE(mw.message.has_value(), !mw.error.empty()) << printable(frame);
      ASSERT_NE(client.command.has_value(), !client.error.empty()) << printable(frame);
      (mw.message || client.command ? accepted : rejected) += 1;
    }
  }
  EXPECT_GT(rejected, 0);
  EXPECT_GT(accepted, 0);
}

}  // namespace
}  // namespace vrd::weart
