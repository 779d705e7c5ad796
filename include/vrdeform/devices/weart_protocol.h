#pragma once
// The WEART middleware wire protocol (TouchDIVER G1 and Pro), both directions, as pure functions:
// frames are ASCII text ended by '~'; each is either "ID:field:..." (CSV) or a JSON object
// {"type":..., "ts":..., "data":{...}}. Written from ../shared/reference/weart-protocol.md (section
// numbers below refer to it). No sockets here: the client and the fake middleware use these.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace vrd::weart {

enum class HandSide : std::uint8_t { Left, Right };
/// Actuation points (§3.2). Wire names THUMB, INDEX, MIDDLE, ANNULAR, PINKY, PALM.
enum class Point : std::uint8_t { Thumb, Index, Middle, Annular, Pinky, Palm };
inline constexpr int kPointCount = 6;

std::string_view wireName(HandSide hand);  ///< "LEFT" / "RIGHT"
std::string_view wireName(Point point);    ///< "THUMB" ... "PALM"
/// The inverse of wireName: exact upper-case names only ("right" is not a hand side).
std::optional<HandSide> handSideFromWire(std::string_view name);
std::optional<Point> pointFromWire(std::string_view name);

/// The parsers reject a frame longer than this (real frames are a few hundred bytes) ...
inline constexpr std::size_t kMaxParsedFrame = 64 * 1024;
/// ... and JSON nested deeper than this (real frames nest 6 levels at most).
inline constexpr int kMaxJsonDepth = 16;

/// Cuts a byte stream into frames at '~' (§2, §10): trims whitespace, skips empty frames, keeps an
/// incomplete tail for the next feed. A frame longer than `maxFrame` bytes is thrown away whole
/// (counted in dropped()): as soon as its tail passes the cap, and the bytes up to its '~' with it,
/// so a stream that never sends '~' holds at most `maxFrame` bytes. Chunking never changes the result.
class FrameSplitter {
 public:
  explicit FrameSplitter(std::size_t maxFrame = 1 << 20) : maxFrame_(maxFrame) {}
  /// Appends `bytes` and the complete frames in them to `frames`.
  void feed(std::string_view bytes, std::vector<std::string>& frames);
  std::size_t dropped() const { return dropped_; }       ///< over-long frames thrown away
  std::size_t buffered() const { return tail_.size(); }  ///< incomplete tail held, never above maxFrame
  void reset();                                          ///< forgets the tail and the dropped count (a new connection)

 private:
  std::size_t maxFrame_;
  std::string tail_;
  bool skipping_ = false;  // inside an over-long frame: discard up to the next '~'
  std::size_t dropped_ = 0;
};

// --- Middleware -> client ----------------------------------------------------------------------

/// MW_STATUS (G1) or WA_STATUS (Pro) (§7.5, §7.6).
struct MiddlewareStatus {
  bool pro = false;    ///< came as WA_STATUS
  std::string status;  ///< "IDLE", "RUNNING", ... (§3.3)
  std::string version;
  int statusCode = 0;  ///< 0 = OK (§8)
  std::string errorDesc;
  int warningCode = 0;
  std::string warningDesc;
  bool actuationsEnabled = true;
  struct Device {
    std::string macAddress;
    HandSide hand = HandSide::Right;
  };
  std::vector<Device> connectedDevices;
  // WA_STATUS only (§7.6); "" / false when not sent. statusFrame writes "NONE" and
  // "PhysicalDevices" for an empty connectionType / deviceSelection.
  std::string connectionType;  ///< "NONE", "BLE", "WIFI", "USB"
  bool autoconnection = false;
  std::string deviceSelection;  ///< "VirtualDevices", "PhysicalDevices"
  bool trackingPlayback = false;
  bool rawDataLog = false;
  bool sensorOnMask = false;
};

/// DEVICES_STATUS (G1) or WEART_TD_PRO_STATUS (Pro) (§7.7, §7.8), the fields both share.
struct DevicesStatus {
  bool pro = false;
  struct Node {
    Point point = Point::Thumb;
    bool connected = false;
    int statusCode = 0;  ///< G1 thimbles; 0 for Pro nodes
    std::string errorDesc;
  };
  /// The Pro master's links (§7.8 master.connection).
  struct Connection {
    bool bluetoothOn = false;
    bool bluetoothConnected = false;
    bool wifiOn = false;
    bool wifiConnected = false;
    bool usbConnected = false;
  };
  struct Device {
    std::string macAddress;
    HandSide hand = HandSide::Right;
    int batteryLevel = 0;
    bool charging = false;
    std::vector<Node> nodes;
    // WEART_TD_PRO_STATUS only (§7.8); devicesFrame writes them for a Pro, the parser reads them when sent.
    double signalStrength = 0.0;   ///< RSSI in dBm (written 0 when not finite)
    std::string sensorsCalibDate;  ///< ISO-8601 UTC, e.g. "2026-02-03T09:03:03Z"
    Connection connection;
  };
  std::vector<Device> devices;
};

/// One hand's tracking: closures in [0, 1] per point (NaN where the message carries none), the
/// thumb abduction in [0, 1] (NaN when not carried: legacy DEFAULT Tracking), and the wrist
/// orientation when a Pro sends it (x, y, z, w; normalised).
struct HandTracking {
  HandSide hand = HandSide::Right;
  std::array<float, kPointCount> closure{};
  float thumbAbduction = 0.0f;
  std::optional<std::array<float, 4>> wristQuaternion;
};

/// `Tracking` (G1 CSV, both hands, TrackType1 or the legacy DEFAULT order, §7.3; hands[0] is the
/// right hand, hands[1] the left) or `TRACKING_BENDING_G2` (Pro JSON, one hand, §7.4).
struct Tracking {
  std::vector<HandTracking> hands;
};

struct CalibrationStatus {  ///< §7.1: 0 idle, 1 calibrating, 2 running
  HandSide hand;
  int status;
};
struct CalibrationResult {  ///< §7.2
  HandSide hand;
  bool success;
};
/// RAW_DATA / RAW_DATA_TD_PRO / RAW_SENSOR_ON_MASK (§7.9-7.11): which sensors sent a sample; the
/// sample values are not decoded.
struct RawData {
  std::string type;
  HandSide hand;
  std::vector<Point> points;  ///< the point keys present (objects), in Point order
};
struct Exit {};        ///< "exit" (§7.12)
struct Disconnect {};  ///< "disconnect" (§7.12)
struct Unknown {       ///< a well-formed frame with an ID we do not handle (ignored, §2.1)
  std::string id;
};

using MiddlewareMessage = std::variant<MiddlewareStatus, DevicesStatus, Tracking, CalibrationStatus, CalibrationResult,
                                       RawData, Exit, Disconnect, Unknown>;

/// A parsed frame, or why it could not be parsed (wrong field count, bad number, bad JSON, a JSON
/// frame without an integer ts, a value out of range). Never throws.
/// Frames bigger than kMaxParsedFrame or nested deeper than kMaxJsonDepth, control bytes (other than
/// tab, CR, LF) and non-ASCII outside JSON strings are errors too. The frame is trimmed, and one
/// trailing '~' is allowed. Unknown carries well-formed frames whose ID (a letter, then [A-Za-z0-9_]) we ignore.
/// TRACKING_BENDING_G2 values must be finite numbers and are clamped to [0, 1] (sensor overshoot
/// does not drop a frame); G1 Tracking values must be integers 0-255. JSON fields must have their
/// types (a float statusCode, a string boolean are errors); status keys left out take the defaults
/// below; enum strings are upper case ("right", "running" are errors).
struct ParsedMiddleware {
  std::optional<MiddlewareMessage> message;
  std::string error;
  std::uint64_t timestampMs = 0;  ///< a JSON frame's ts; 0 for CSV frames
};
ParsedMiddleware parseMiddlewareFrame(std::string_view frame);

// --- Client -> middleware ------------------------------------------------------------------------

/// Every client frame below ends with its '~'. Values are clamped to their ranges (§10) and NaN
/// reads as 0; numbers are written locale-independently as the shortest decimal that reads back
/// as the same float, never in exponent notation (|v| < 1e-6 is written 0): "0.8", "0", "100".
std::string startFrame();  ///< "StartFromClient:SdkLLCPP:2.0.0:TrackType1~" (§6.1)
std::string stopFrame();   ///< "StopFromClient~"
std::string startCalibrationFrame();
std::string stopCalibrationFrame();
std::string forceFrame(HandSide hand, Point point, float value);  ///< force:v:0:0:HAND:POINT (§6.4)
std::string stopForceFrame(HandSide hand, Point point);
std::string temperatureFrame(HandSide hand, Point point, float value);  ///< [0, 1], 0.5 neutral, NaN -> 0.5 (§6.3)
std::string stopTemperatureFrame(HandSide hand, Point point);
/// §6.5: index 0-21 (anything else becomes 255), velocity [0, 0.5], volume [0, 100].
std::string textureFrame(HandSide hand, Point point, int index, float velocity, float volume);
std::string stopTextureFrame(HandSide hand, Point point);
/// A JSON request with no payload (§6.7): MW_GET_STATUS, DEVICES_GET_STATUS, RAW_DATA_ON, RAW_DATA_OFF.
std::string requestFrame(std::string_view type, std::uint64_t timestampMs);

// --- The middleware side (for the fake middleware and tests) ------------------------------------

/// A client frame as the middleware sees it.
struct ClientCommand {
  enum class Kind : std::uint8_t {
    Start,
    Stop,
    StartCalibration,
    StopCalibration,
    Force,
    StopForce,
    Temperature,
    StopTemperature,
    Texture,
    StopTexture,
    Request,
    ResetCalibration,  ///< C# 2.x only, meaning undocumented (§6.2); parsed, never sent by us
  };
  Kind kind = Kind::Start;
  HandSide hand = HandSide::Right;
  Point point = Point::Thumb;
  float value = 0.0f;  ///< force / temperature value, texture velocity
  int textureIndex = 0;
  float volume = 0.0f;
  std::string text;     ///< Start: the track type ("" for a bare start); Request: the JSON type
  std::string sdkType;  ///< Start: e.g. "SdkLLCPP" ("" for a bare start)
  std::string sdkVersion;
  std::uint64_t timestampMs = 0;  ///< Request: ts
};
/// Strict: exact field counts, numbers in their ranges (force, temperature [0, 1]; texture index
/// 0-21 or 255, vx, vy [0, 1], velocity [0, 0.5], volume [0, 100]; out of range is an error, not
/// clamped), upper-case hand and point names; JSON requests need an integer ts, any key order.
/// Same size, depth, byte and trailing-'~' rules as parseMiddlewareFrame.
struct ParsedClient {
  std::optional<ClientCommand> command;
  std::string error;  ///< malformed, or an unknown ID
};
ParsedClient parseClientFrame(std::string_view frame);

/// Middleware frames (with '~'), JSON keys in the order type, ts, data (§11), every key of the
/// message present, real booleans. Strings are written as ASCII: JSON escapes for non-ASCII and for '~' (U+007E).
std::string statusFrame(const MiddlewareStatus& status, std::uint64_t timestampMs);
std::string devicesFrame(const DevicesStatus& devices, std::uint64_t timestampMs);
/// The G1 `Tracking` layouts (§7.3): DEFAULT follows a bare StartFromClient, TrackType1 a start that names it.
enum class TrackType : std::uint8_t { Default, TrackType1 };
/// G1: `Tracking` with both hands, closures rounded to 0-255; TrackType1 (§7.3.2) carries index,
/// thumb, thumb abduction and middle, DEFAULT (§7.3.1) thumb, index, middle and palm. A hand
/// missing from `hands` reads 0.
std::string trackingG1Frame(const std::vector<HandTracking>& hands, TrackType type = TrackType::TrackType1);
/// Pro: TRACKING_BENDING_G2 for one hand (§7.4); NaN closures are sent as 0.
std::string trackingG2Frame(const HandTracking& hand, std::uint64_t timestampMs);
/// One sensor's sample in RAW_DATA / RAW_DATA_TD_PRO (§7.9, §7.10): accelerometer in g, gyroscope
/// in deg/s, time-of-flight distance in mm (G1 only; the palm has no such sensor and reads 0).
struct RawSample {
  Point point = Point::Index;
  std::array<float, 3> accelerometer{};
  std::array<float, 3> gyroscope{};
  int distance = 0;
};
/// RAW_DATA (G1, with timeOfFlight) or RAW_DATA_TD_PRO (Pro, without) for one hand, the samples in
/// the order given.
std::string rawDataFrame(HandSide hand, const std::vector<RawSample>& samples, bool pro, std::uint64_t timestampMs);
std::string calibrationStatusFrame(HandSide hand, int status);  ///< `status` written as given
std::string calibrationResultFrame(HandSide hand, bool success);

}  // namespace vrd::weart
