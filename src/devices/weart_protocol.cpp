// The WEART middleware wire protocol (weart_protocol.h): frame splitting, the strict parsers of both
// directions and the frame formatters. Written from ../shared/reference/weart-protocol.md; the section
// numbers refer to it. Nothing here throws to the caller, whatever the bytes.
#include "vrdeform/devices/weart_protocol.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <exception>
#include <limits>
#include <nlohmann/json.hpp>
#include <system_error>
#include <utility>

#include "vrdeform/core/json_depth.h"

namespace vrd::weart {
namespace {

using Json = nlohmann::json;
using OrderedJson = nlohmann::ordered_json;

constexpr std::string_view kHandNames[] = {"LEFT", "RIGHT"};
constexpr std::string_view kPointNames[] = {"THUMB", "INDEX", "MIDDLE", "ANNULAR", "PINKY", "PALM"};
constexpr const char* kPointKeys[] = {"thumb", "index", "middle", "annular", "pinky", "palm"};  // JSON payload keys
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

bool isFrameSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }
bool isDigit(char c) { return c >= '0' && c <= '9'; }
bool isIdChar(char c) { return isDigit(c) || (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && isFrameSpace(s.front())) s.remove_prefix(1);
  while (!s.empty() && isFrameSpace(s.back())) s.remove_suffix(1);
  return s;
}

/// A message ID: a letter, then [A-Za-z0-9_].
bool isIdentifier(std::string_view s) {
  return !s.empty() && ((s[0] >= 'A' && s[0] <= 'Z') || (s[0] >= 'a' && s[0] <= 'z')) &&
         std::all_of(s.begin(), s.end(), isIdChar);
}

/// An upper-case enum value as the middleware writes them (§3.3): [A-Z_]*, "" for none.
bool isUpperEnum(std::string_view s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return (c >= 'A' && c <= 'Z') || c == '_'; });
}

std::string hexByte(unsigned char c) {
  constexpr char kHex[] = "0123456789abcdef";
  return std::string("0x") + kHex[c >> 4] + kHex[c & 15];
}

std::string shown(std::string_view s) {  // for error messages: at most 40 bytes, printable ASCII only
  std::string out = "'";
  for (std::size_t i = 0; i < s.size() && i < 40; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    out += (c >= 0x20 && c < 0x7f) ? static_cast<char>(c) : '?';
  }
  return out + (s.size() > 40 ? "...'" : "'");
}

// --- Numbers ---------------------------------------------------------------------------------------

/// A strict unsigned decimal: 1-10 digits, nothing else (no sign, space, point or exponent), <= max.
std::optional<std::uint32_t> parseUint(std::string_view s, std::uint32_t max) {
  if (s.empty() || s.size() > 10 || !std::all_of(s.begin(), s.end(), isDigit)) return std::nullopt;
  std::uint64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || v > max) return std::nullopt;
  return static_cast<std::uint32_t>(v);
}

/// A strict decimal float as any SDK writes it (§2.2): -?digits[.digits][e[+-]digits], at least one
/// mantissa digit, finite ("0.800000", "0.8", "0", "1e-05"). No "inf", "nan", hex, '+' or spaces.
std::optional<double> parseDecimal(std::string_view s) {
  if (s.empty() || s.size() > 64) return std::nullopt;
  std::size_t i = 0, digits = 0;
  if (s[i] == '-') ++i;
  for (; i < s.size() && isDigit(s[i]); ++i) ++digits;
  if (i < s.size() && s[i] == '.')
    for (++i; i < s.size() && isDigit(s[i]); ++i) ++digits;
  if (digits == 0) return std::nullopt;
  if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) ++i;
    std::size_t exponentDigits = 0;
    for (; i < s.size() && isDigit(s[i]); ++i) ++exponentDigits;
    if (exponentDigits == 0) return std::nullopt;
  }
  if (i != s.size()) return std::nullopt;
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::optional<double> parseDecimalIn(std::string_view s, double lo, double hi) {
  const auto v = parseDecimal(s);
  if (!v || *v < lo || *v > hi) return std::nullopt;
  return v;
}

/// NaN and negatives -> 0, above `hi` -> hi.
float clampTo(float v, float hi) {
  if (!(v >= 0.0f)) return 0.0f;
  return v > hi ? hi : v;
}

void appendInt(std::string& out, long long v) {
  char buf[24];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

/// The float spelling of every frame we write: shortest round-trip decimal, fixed notation, '.' in
/// every locale; NaN and |v| < 1e-6 (and -0) are written "0".
void appendFloat(std::string& out, float v) {
  if (!(std::fabs(v) >= 1e-6f)) v = 0.0f;
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed);
  if (r.ec != std::errc()) {  // cannot happen for a float in 64 bytes; stay defined anyway
    out += '0';
    return;
  }
  out.append(buf, r.ptr);
}

/// The double whose shortest spelling is the float's ("0.31", not 0.3100000023841858), for JSON.
double wireDouble(float v) {
  if (!std::isfinite(v) || std::fabs(v) < 1e-6f) return 0.0;
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  double d = 0.0;
  if (r.ec != std::errc() || std::from_chars(buf, r.ptr, d).ec != std::errc()) return static_cast<double>(v);
  return d;
}

// --- Frames ----------------------------------------------------------------------------------------

/// The checks both parsers share: size, trimming, one trailing '~', bytes, JSON depth.
struct Prepared {
  std::string_view text;
  bool json = false;
  std::string error;
};

Prepared prepare(std::string_view frame) {
  Prepared p;
  if (frame.size() > kMaxParsedFrame) {
    p.error = "frame of " + std::to_string(frame.size()) + " bytes, over the " + std::to_string(kMaxParsedFrame) +
              "-byte limit";
    return p;
  }
  std::string_view s = trim(frame);
  if (!s.empty() && s.back() == '~') s = trim(s.substr(0, s.size() - 1));
  if (s.empty()) {
    p.error = "empty frame";
    return p;
  }
  p.json = s.front() == '{' || s.front() == '[';
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c == '~') {
      p.error = "'~' inside a frame at byte " + std::to_string(i);
      return p;
    }
    if ((c < 0x20 && !isFrameSpace(static_cast<char>(c))) || c == 0x7f) {
      p.error = "control byte " + hexByte(c) + " at byte " + std::to_string(i);
      return p;
    }
    if (c >= 0x80 && !p.json) {  // JSON strings may hold UTF-8, which the JSON parser validates
      p.error = "non-ASCII byte " + hexByte(c) + " at byte " + std::to_string(i);
      return p;
    }
  }
  if (p.json && !jsonDepthWithin(s, kMaxJsonDepth)) {
    p.error = "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels";
    return p;
  }
  p.text = s;
  return p;
}

/// CSV fields split on ':'; more than kMaxFields sets tooMany (no message has more than 10).
constexpr std::size_t kMaxFields = 12;
struct Fields {
  std::array<std::string_view, kMaxFields> at{};
  std::size_t count = 0;
  bool tooMany = false;
};

Fields splitFields(std::string_view s) {
  Fields f;
  for (;;) {
    if (f.count == kMaxFields) {
      f.tooMany = true;
      return f;
    }
    const auto colon = s.find(':');
    f.at[f.count++] = s.substr(0, colon);
    if (colon == std::string_view::npos) return f;
    s.remove_prefix(colon + 1);
  }
}

std::string fieldCountError(std::string_view id, std::size_t expected, const Fields& f) {
  return std::string(id) + " needs " + std::to_string(expected) + " fields, got " +
         (f.tooMany ? "more than " + std::to_string(kMaxFields - 1) : std::to_string(f.count - 1));
}

/// Parses a JSON frame into an object with a string `type` and an unsigned integer `ts`.
struct Envelope {
  Json root;
  std::string type;
  std::uint64_t ts = 0;
  const Json* data = nullptr;  ///< `data` when it is present and an object
  bool dataWrongType = false;  ///< `data` present but not an object
  std::string error;
};

/// Fills `e` (an out-parameter: `data` points into `root`).
void parseEnvelope(std::string_view s, Envelope& e) {
  e.root = Json::parse(s.data(), s.data() + s.size(), nullptr, /*allow_exceptions=*/false);
  if (e.root.is_discarded()) {
    e.error = "invalid JSON";
    return;
  }
  if (!e.root.is_object()) {
    e.error = "JSON frame is not an object";
    return;
  }
  const auto type = e.root.find("type");
  if (type == e.root.end() || !type->is_string()) {
    e.error = "JSON frame without a string \"type\"";
    return;
  }
  e.type = type->get<std::string>();
  if (!isIdentifier(e.type)) {
    e.error = "malformed JSON type " + shown(e.type);
    return;
  }
  const auto ts = e.root.find("ts");
  if (ts == e.root.end()) {
    e.error = "JSON frame without \"ts\"";
    return;
  }
  if (ts->is_number_unsigned()) {
    e.ts = ts->get<std::uint64_t>();
  } else if (ts->is_number_integer() && ts->get<std::int64_t>() == 0) {  // "-0"
    e.ts = 0;
  } else {
    e.error = "JSON \"ts\" is not a non-negative integer";
    return;
  }
  const auto data = e.root.find("data");
  if (data != e.root.end()) {
    if (data->is_object())
      e.data = &*data;
    else
      e.dataWrongType = true;
  }
}

// --- JSON field readers: false and `error` set on a wrong type or a missing required key ----------

class Reader {
 public:
  std::string error;

  const Json* find(const Json& obj, const char* key, bool required) {
    const auto it = obj.find(key);
    if (it == obj.end()) {
      if (required) fail(key, "is missing");
      return nullptr;
    }
    return &*it;
  }
  bool string(const Json& obj, const char* key, std::string& out, bool required = false) {
    const Json* v = find(obj, key, required);
    if (!v) return error.empty();
    if (!v->is_string()) return fail(key, "is not a string");
    out = v->get<std::string>();
    return true;
  }
  bool upperEnum(const Json& obj, const char* key, std::string& out) {
    if (!string(obj, key, out)) return false;
    if (obj.contains(key) && !isUpperEnum(out)) return fail(key, "is not an upper-case enum value");
    return true;
  }
  bool boolean(const Json& obj, const char* key, bool& out) {
    const Json* v = find(obj, key, false);
    if (!v) return true;
    if (!v->is_boolean()) return fail(key, "is not a boolean");
    out = v->get<bool>();
    return true;
  }
  bool integer(const Json& obj, const char* key, int& out) {
    const Json* v = find(obj, key, false);
    if (!v) return true;
    if (v->is_number_unsigned()) {
      const auto u = v->get<std::uint64_t>();
      if (u > static_cast<std::uint64_t>(std::numeric_limits<int>::max())) return fail(key, "is out of range");
      out = static_cast<int>(u);
      return true;
    }
    if (!v->is_number_integer()) return fail(key, "is not an integer");
    const auto i = v->get<std::int64_t>();
    if (i < std::numeric_limits<int>::min() || i > std::numeric_limits<int>::max()) return fail(key, "is out of range");
    out = static_cast<int>(i);
    return true;
  }
  bool number(const Json& obj, const char* key, double& out, bool required) {
    const Json* v = find(obj, key, required);
    if (!v) return error.empty();
    if (!v->is_number()) return fail(key, "is not a number");
    out = v->get<double>();
    if (!std::isfinite(out)) return fail(key, "is not finite");
    return true;
  }
  /// A finite number clamped to [0, 1].
  bool unit(const Json& obj, const char* key, float& out, bool required) {
    double v = 0.0;
    if (!number(obj, key, v, required)) return false;
    if (obj.contains(key)) out = static_cast<float>(std::clamp(v, 0.0, 1.0));
    return true;
  }
  bool hand(const Json& obj, const char* key, HandSide& out) {
    std::string name;
    if (!string(obj, key, name, true)) return false;
    const auto h = handSideFromWire(name);
    if (!h) return fail(key, "is not LEFT or RIGHT: " + shown(name));
    out = *h;
    return true;
  }
  bool point(const Json& obj, const char* key, Point& out) {
    std::string name;
    if (!string(obj, key, name, true)) return false;
    const auto p = pointFromWire(name);
    if (!p) return fail(key, "is not an actuation point: " + shown(name));
    out = *p;
    return true;
  }
  const Json* object(const Json& obj, const char* key, bool required) {
    const Json* v = find(obj, key, required);
    if (v && !v->is_object()) {
      fail(key, "is not an object");
      return nullptr;
    }
    return v;
  }
  const Json* array(const Json& obj, const char* key, bool required) {
    const Json* v = find(obj, key, required);
    if (v && !v->is_array()) {
      fail(key, "is not an array");
      return nullptr;
    }
    return v;
  }
  bool fail(std::string_view key, std::string_view what) {
    if (error.empty()) error = "\"" + std::string(key) + "\" " + std::string(what);
    return false;
  }
};

// --- Middleware -> client: the messages -------------------------------------------------------

ParsedMiddleware failed(std::string error) {
  ParsedMiddleware r;
  r.error = std::move(error);
  return r;
}

ParsedMiddleware parsedStatus(const Envelope& e, bool pro) {
  MiddlewareStatus st;
  st.pro = pro;
  Reader r;
  if (e.data) {
    const Json& d = *e.data;
    if (!r.upperEnum(d, "status", st.status) || !r.string(d, "version", st.version) ||
        !r.integer(d, "statusCode", st.statusCode) || !r.string(d, "errorDesc", st.errorDesc) ||
        !r.integer(d, "warningCode", st.warningCode) || !r.string(d, "warningDesc", st.warningDesc) ||
        !r.boolean(d, "actuationsEnabled", st.actuationsEnabled) ||
        !r.upperEnum(d, "connectionType", st.connectionType) || !r.boolean(d, "autoconnection", st.autoconnection) ||
        !r.string(d, "deviceSelection", st.deviceSelection) || !r.boolean(d, "trackingPlayback", st.trackingPlayback) ||
        !r.boolean(d, "rawDataLog", st.rawDataLog) || !r.boolean(d, "sensorOnMask", st.sensorOnMask))
      return failed(e.type + ": " + r.error);
    if (const Json* devices = r.array(d, "connectedDevices", false)) {
      for (const Json& item : *devices) {
        if (!item.is_object()) return failed(e.type + ": a connectedDevices entry is not an object");
        MiddlewareStatus::Device dev;
        if (!r.string(item, "macAddress", dev.macAddress, true) || !r.hand(item, "handSide", dev.hand))
          return failed(e.type + ": connectedDevices: " + r.error);
        st.connectedDevices.push_back(std::move(dev));
      }
    }
    if (!r.error.empty()) return failed(e.type + ": " + r.error);
  }
  ParsedMiddleware out;
  out.message = std::move(st);
  return out;
}

ParsedMiddleware parsedDevices(const Envelope& e, bool pro) {
  if (!e.data) return failed(e.type + ": no data object");
  Reader r;
  const Json* devices = r.array(*e.data, "devices", true);
  if (!devices) return failed(e.type + ": " + r.error);
  DevicesStatus out;
  out.pro = pro;
  for (const Json& item : *devices) {
    if (!item.is_object()) return failed(e.type + ": a devices entry is not an object");
    DevicesStatus::Device dev;
    if (!r.string(item, "macAddress", dev.macAddress, true) || !r.hand(item, "handSide", dev.hand))
      return failed(e.type + ": " + r.error);
    const Json* battery = &item;  // G1: on the device; Pro: in "master"
    if (pro) {
      battery = r.object(item, "master", false);
      if (!r.error.empty()) return failed(e.type + ": " + r.error);
      if (!r.number(item, "signalStrength", dev.signalStrength, false) ||
          !r.string(item, "sensorsCalibDate", dev.sensorsCalibDate))
        return failed(e.type + ": " + r.error);
      if (const Json* link = battery ? r.object(*battery, "connection", false) : nullptr) {
        DevicesStatus::Connection& c = dev.connection;
        if (!r.boolean(*link, "bluetoothOn", c.bluetoothOn) ||
            !r.boolean(*link, "bluetoothConnected", c.bluetoothConnected) || !r.boolean(*link, "wifiOn", c.wifiOn) ||
            !r.boolean(*link, "wifiConnected", c.wifiConnected) || !r.boolean(*link, "usbConnected", c.usbConnected))
          return failed(e.type + ": connection: " + r.error);
      }
      if (!r.error.empty()) return failed(e.type + ": " + r.error);
    }
    if (battery &&
        (!r.integer(*battery, "batteryLevel", dev.batteryLevel) || !r.boolean(*battery, "charging", dev.charging)))
      return failed(e.type + ": " + r.error);
    const Json* nodes = r.array(item, pro ? "nodes" : "thimbles", false);
    if (!r.error.empty()) return failed(e.type + ": " + r.error);
    if (nodes) {
      for (const Json& n : *nodes) {
        if (!n.is_object()) return failed(e.type + ": a node entry is not an object");
        DevicesStatus::Node node;
        bool fault = false;
        if (!r.point(n, "id", node.point) || !r.boolean(n, "connected", node.connected) ||
            !r.integer(n, "statusCode", node.statusCode) || !r.string(n, "errorDesc", node.errorDesc) ||
            !r.boolean(n, "imuFault", fault) || !r.boolean(n, "adcFault", fault) || !r.boolean(n, "tofFault", fault))
          return failed(e.type + ": " + r.error);
        dev.nodes.push_back(std::move(node));
      }
    }
    out.devices.push_back(std::move(dev));
  }
  ParsedMiddleware result;
  result.message = std::move(out);
  return result;
}

ParsedMiddleware parsedTrackingG2(const Envelope& e) {
  if (!e.data) return failed(e.type + ": no data object");
  const Json& d = *e.data;
  Reader r;
  HandTracking hand;
  if (!r.hand(d, "handSide", hand.hand)) return failed(e.type + ": " + r.error);
  for (int p = 0; p < kPointCount; ++p) {
    const Json* node = r.object(d, kPointKeys[p], true);
    if (!node) return failed(e.type + ": " + r.error);
    float abduction = 0.0f;
    const bool thumb = static_cast<Point>(p) == Point::Thumb;
    if (!r.unit(*node, "closure", hand.closure[static_cast<std::size_t>(p)], true) ||
        !r.unit(*node, "abduction", thumb ? hand.thumbAbduction : abduction, thumb))
      return failed(e.type + ": " + kPointKeys[p] + ": " + r.error);
  }
  if (const Json* wrist = r.object(d, "wrist", false)) {
    const Json* q = r.object(*wrist, "quaternion", true);
    if (!q) return failed(e.type + ": wrist: " + r.error);
    std::array<double, 4> v{};
    if (!r.number(*q, "x", v[0], true) || !r.number(*q, "y", v[1], true) || !r.number(*q, "z", v[2], true) ||
        !r.number(*q, "w", v[3], true))
      return failed(e.type + ": wrist quaternion: " + r.error);
    // Scale before squaring so that huge components cannot overflow.
    const double scale = std::max({std::fabs(v[0]), std::fabs(v[1]), std::fabs(v[2]), std::fabs(v[3])});
    if (!(scale > 1e-12)) return failed(e.type + ": wrist quaternion is zero");
    double norm2 = 0.0;
    for (double& c : v) {
      c /= scale;
      norm2 += c * c;
    }
    const double norm = std::sqrt(norm2);
    std::array<float, 4> quat{};
    for (std::size_t i = 0; i < 4; ++i) quat[i] = static_cast<float>(v[i] / norm);
    hand.wristQuaternion = quat;
  }
  if (!r.error.empty()) return failed(e.type + ": " + r.error);
  ParsedMiddleware out;
  out.message = Tracking{{hand}};
  return out;
}

ParsedMiddleware parsedRawData(const Envelope& e) {
  if (!e.data) return failed(e.type + ": no data object");
  Reader r;
  RawData raw{e.type, HandSide::Right, {}};
  if (!r.hand(*e.data, "handSide", raw.hand)) return failed(e.type + ": " + r.error);
  for (int p = 0; p < kPointCount; ++p) {
    if (r.object(*e.data, kPointKeys[p], false)) raw.points.push_back(static_cast<Point>(p));
    if (!r.error.empty()) return failed(e.type + ": " + r.error);
  }
  ParsedMiddleware out;
  out.message = std::move(raw);
  return out;
}

ParsedMiddleware parseMiddlewareJson(std::string_view s) {
  Envelope e;
  parseEnvelope(s, e);
  if (!e.error.empty()) return failed(std::move(e.error));
  const std::string& id = e.type;
  const bool known = id == "MW_STATUS" || id == "WA_STATUS" || id == "DEVICES_STATUS" || id == "WEART_TD_PRO_STATUS" ||
                     id == "TRACKING_BENDING_G2" || id == "RAW_DATA" || id == "RAW_DATA_TD_PRO" ||
                     id == "RAW_SENSOR_ON_MASK";
  ParsedMiddleware out;
  if (!known) {
    out.message = Unknown{id};
  } else if (e.dataWrongType) {
    out.error = id + ": \"data\" is not an object";
  } else if (id == "MW_STATUS" || id == "WA_STATUS") {
    out = parsedStatus(e, id == "WA_STATUS");
  } else if (id == "DEVICES_STATUS" || id == "WEART_TD_PRO_STATUS") {
    out = parsedDevices(e, id == "WEART_TD_PRO_STATUS");
  } else if (id == "TRACKING_BENDING_G2") {
    out = parsedTrackingG2(e);
  } else {
    out = parsedRawData(e);
  }
  if (out.message) out.timestampMs = e.ts;
  return out;
}

HandTracking untracked(HandSide side) {
  HandTracking h;
  h.hand = side;
  h.closure.fill(kNaN);
  h.thumbAbduction = kNaN;
  return h;
}

/// `Tracking` (§7.3): TrackType1 (9 fields) or the legacy DEFAULT order (8 fields), integers 0-255.
ParsedMiddleware parseTrackingCsv(const Fields& f) {
  const bool type1 = f.count >= 2 && f.at[1] == "TrackType1";
  const std::size_t first = type1 ? 2 : 1;
  if (f.tooMany || f.count != first + 8)
    return failed(type1 ? fieldCountError("Tracking:TrackType1", 9, f) : fieldCountError("Tracking", 8, f));
  std::array<float, 8> v{};
  for (std::size_t i = 0; i < 8; ++i) {
    const auto n = parseUint(f.at[first + i], 255);
    if (!n)
      return failed("Tracking: value " + std::to_string(i + 1) + " is not an integer 0-255: " + shown(f.at[first + i]));
    v[i] = static_cast<float>(*n) / 255.0f;
  }
  Tracking t;
  for (int h = 0; h < 2; ++h) {  // the right hand's values come first (§3.1)
    HandTracking hand = untracked(h == 0 ? HandSide::Right : HandSide::Left);
    const float* x = v.data() + 4 * h;
    auto set = [&hand](Point p, float value) { hand.closure[static_cast<std::size_t>(p)] = value; };
    if (type1) {  // index, thumb, thumb abduction, middle
      set(Point::Index, x[0]);
      set(Point::Thumb, x[1]);
      hand.thumbAbduction = x[2];
      set(Point::Middle, x[3]);
    } else {  // thumb, index, middle, palm
      set(Point::Thumb, x[0]);
      set(Point::Index, x[1]);
      set(Point::Middle, x[2]);
      set(Point::Palm, x[3]);
    }
    t.hands.push_back(hand);
  }
  ParsedMiddleware out;
  out.message = std::move(t);
  return out;
}

ParsedMiddleware parseMiddlewareCsv(std::string_view s) {
  const Fields f = splitFields(s);
  const std::string_view id = f.at[0];
  if (!isIdentifier(id)) return failed("malformed message ID " + shown(id));
  ParsedMiddleware out;
  if (id == "Tracking") return parseTrackingCsv(f);
  if (id == "CalibrationStatus" || id == "CalibrationResult") {
    const bool status = id == "CalibrationStatus";
    if (f.tooMany || f.count != 3) return failed(fieldCountError(id, 2, f));
    const auto hand = parseUint(f.at[1], 1);
    if (!hand) return failed(std::string(id) + ": hand is not 0 or 1: " + shown(f.at[1]));
    const HandSide side = *hand == 0 ? HandSide::Left : HandSide::Right;
    const auto code = parseUint(f.at[2], status ? 2 : 1);
    if (!code)
      return failed(std::string(id) + (status ? ": status is not 0-2: " : ": result is not 0 or 1: ") + shown(f.at[2]));
    if (status)
      out.message = CalibrationStatus{side, static_cast<int>(*code)};
    else
      out.message = CalibrationResult{side, *code == 0};
    return out;
  }
  if (id == "exit" || id == "disconnect") {
    if (f.count != 1) return failed(std::string(id) + " takes no fields");
    if (id == "exit")
      out.message = Exit{};
    else
      out.message = Disconnect{};
    return out;
  }
  out.message = Unknown{std::string(id)};
  return out;
}

// --- Client -> middleware, as the middleware sees it --------------------------------------------

ParsedClient clientError(std::string error) {
  ParsedClient r;
  r.error = std::move(error);
  return r;
}

/// HAND:POINT at f.at[i], f.at[i + 1].
bool readTarget(const Fields& f, std::size_t i, ClientCommand& c, std::string& error) {
  const auto hand = handSideFromWire(f.at[i]);
  const auto point = pointFromWire(f.at[i + 1]);
  if (!hand)
    error = std::string(f.at[0]) + ": hand side is not LEFT or RIGHT: " + shown(f.at[i]);
  else if (!point)
    error = std::string(f.at[0]) + ": not an actuation point: " + shown(f.at[i + 1]);
  if (!error.empty()) return false;
  c.hand = *hand;
  c.point = *point;
  return true;
}

ParsedClient parseClientCsv(std::string_view s) {
  const Fields f = splitFields(s);
  const std::string_view id = f.at[0];
  if (!isIdentifier(id)) return clientError("malformed message ID " + shown(id));
  using Kind = ClientCommand::Kind;
  ClientCommand c;
  std::string error;
  auto expect = [&](std::size_t fields) {
    if (f.tooMany || f.count != fields + 1) error = fieldCountError(id, fields, f);
    return error.empty();
  };
  auto value = [&](std::size_t i, float lo, float hi, const char* what, float& out) {
    const auto v = parseDecimalIn(f.at[i], lo, hi);
    if (!v) {
      error = std::string(id) + ": " + what + " is not a number in [";
      appendFloat(error, lo);
      error += ", ";
      appendFloat(error, hi);
      error += "]: " + shown(f.at[i]);
      return false;
    }
    out = static_cast<float>(*v);
    return true;
  };
  if (id == "StartFromClient") {
    c.kind = Kind::Start;
    if (f.count == 4 && !f.tooMany) {
      for (std::size_t i = 1; i < 4; ++i)
        if (f.at[i].empty()) return clientError("StartFromClient: empty field " + std::to_string(i));
      c.sdkType = f.at[1];
      c.sdkVersion = f.at[2];
      c.text = f.at[3];
    } else if (f.count != 1) {
      return clientError("StartFromClient needs 0 or 3 fields, got " +
                         (f.tooMany ? std::string("more") : std::to_string(f.count - 1)));
    }
  } else if (id == "StopFromClient" || id == "StartCalibration" || id == "StopCalibration" ||
             id == "ResetCalibration") {
    if (!expect(0)) return clientError(error);
    c.kind = id == "StopFromClient"     ? Kind::Stop
             : id == "StartCalibration" ? Kind::StartCalibration
             : id == "StopCalibration"  ? Kind::StopCalibration
                                        : Kind::ResetCalibration;
  } else if (id == "temperature") {
    c.kind = Kind::Temperature;
    if (!expect(3) || !value(1, 0.0f, 1.0f, "value", c.value) || !readTarget(f, 2, c, error)) return clientError(error);
  } else if (id == "force") {
    c.kind = Kind::Force;
    float unused = 0.0f;
    if (!expect(5) || !value(1, 0.0f, 1.0f, "f0", c.value) || !value(2, 0.0f, 1.0f, "f1", unused) ||
        !value(3, 0.0f, 1.0f, "f2", unused) || !readTarget(f, 4, c, error))
      return clientError(error);
  } else if (id == "texture") {
    c.kind = Kind::Texture;
    if (!expect(7)) return clientError(error);
    const auto index = parseUint(f.at[1], 255);
    if (!index || (*index > 21 && *index != 255))
      return clientError("texture: index is not 0-21 or 255: " + shown(f.at[1]));
    c.textureIndex = static_cast<int>(*index);
    float unused = 0.0f;
    if (!value(2, 0.0f, 1.0f, "vx", unused) || !value(3, 0.0f, 1.0f, "vy", unused) ||
        !value(4, 0.0f, 0.5f, "velocity", c.value) || !value(5, 0.0f, 100.0f, "volume", c.volume) ||
        !readTarget(f, 6, c, error))
      return clientError(error);
  } else if (id == "stopTemperature" || id == "stopForce" || id == "stopTexture") {
    c.kind = id == "stopTemperature" ? Kind::StopTemperature : id == "stopForce" ? Kind::StopForce : Kind::StopTexture;
    if (!expect(2) || !readTarget(f, 1, c, error)) return clientError(error);
  } else {
    return clientError("unknown client message " + shown(id));
  }
  ParsedClient out;
  out.command = std::move(c);
  return out;
}

ParsedClient parseClientJson(std::string_view s) {
  Envelope e;
  parseEnvelope(s, e);
  if (!e.error.empty()) return clientError(std::move(e.error));
  if (e.type != "MW_GET_STATUS" && e.type != "DEVICES_GET_STATUS" && e.type != "WA_GET_STATUS" &&
      e.type != "RAW_DATA_ON" && e.type != "RAW_DATA_OFF")
    return clientError("unknown client request " + shown(e.type));
  if (e.dataWrongType) return clientError(e.type + ": \"data\" is not an object");
  ClientCommand c;
  c.kind = ClientCommand::Kind::Request;
  c.text = e.type;
  c.timestampMs = e.ts;
  ParsedClient out;
  out.command = std::move(c);
  return out;
}

// --- Formatting ---------------------------------------------------------------------------------

/// Ends a CSV client frame: ":HAND:POINT~".
std::string& endWithTarget(std::string& out, HandSide hand, Point point) {
  out += ':';
  out += wireName(hand);
  out += ':';
  out += wireName(point);
  out += '~';
  return out;
}

std::string targetFrame(std::string_view id, HandSide hand, Point point) {
  std::string out(id);
  return endWithTarget(out, hand, point);
}

std::string jsonFrame(std::string_view type, std::uint64_t ts, const OrderedJson* data) {
  OrderedJson j;
  j["type"] = std::string(type);
  j["ts"] = ts;
  if (data) j["data"] = *data;
  const std::string text = j.dump(-1, ' ', /*ensure_ascii=*/true, OrderedJson::error_handler_t::replace);
  std::string out;
  out.reserve(text.size() + 1);
  for (const char c : text) {
    if (c == '~')
      out += "\\u007e";  // only inside strings: '~' would end the frame (§2)
    else
      out += c;
  }
  out += '~';
  return out;
}

std::string handName(HandSide hand) { return std::string(wireName(hand)); }

}  // namespace

// --- Names ----------------------------------------------------------------------------------------

std::string_view wireName(HandSide hand) { return kHandNames[hand == HandSide::Right ? 1 : 0]; }

std::string_view wireName(Point point) {
  const auto i = static_cast<std::size_t>(point);
  return i < std::size(kPointNames) ? kPointNames[i] : std::string_view("?");
}

std::optional<HandSide> handSideFromWire(std::string_view name) {
  if (name == "LEFT") return HandSide::Left;
  if (name == "RIGHT") return HandSide::Right;
  return std::nullopt;
}

std::optional<Point> pointFromWire(std::string_view name) {
  for (std::size_t i = 0; i < std::size(kPointNames); ++i)
    if (name == kPointNames[i]) return static_cast<Point>(i);
  return std::nullopt;
}

// --- FrameSplitter ----------------------------------------------------------------------------------

void FrameSplitter::feed(std::string_view bytes, std::vector<std::string>& frames) {
  while (!bytes.empty()) {
    const auto end = bytes.find('~');
    const std::string_view piece = bytes.substr(0, end);  // all of it when there is no '~'
    if (skipping_) {
      // The rest of an over-long frame, already counted: thrown away up to and with its '~'.
    } else if (tail_.size() + piece.size() > maxFrame_) {
      ++dropped_;
      tail_.clear();
      tail_.shrink_to_fit();
      skipping_ = end == std::string_view::npos;
    } else if (end == std::string_view::npos) {
      tail_.append(piece);
    } else {
      const std::string_view frame = trim(tail_.empty() ? piece : std::string_view(tail_.append(piece)));
      if (!frame.empty()) frames.emplace_back(frame);
      tail_.clear();
    }
    if (end == std::string_view::npos) return;
    skipping_ = false;
    bytes.remove_prefix(end + 1);
  }
}

void FrameSplitter::reset() {
  tail_.clear();
  tail_.shrink_to_fit();
  skipping_ = false;
  dropped_ = 0;
}

// --- Parsers ----------------------------------------------------------------------------------------

ParsedMiddleware parseMiddlewareFrame(std::string_view frame) {
  try {
    const Prepared p = prepare(frame);
    if (!p.error.empty()) return failed(p.error);
    return p.json ? parseMiddlewareJson(p.text) : parseMiddlewareCsv(p.text);
  } catch (const std::exception& e) {
    return failed(std::string("internal error: ") + e.what());
  } catch (...) {
    return failed("internal error");
  }
}

ParsedClient parseClientFrame(std::string_view frame) {
  try {
    const Prepared p = prepare(frame);
    if (!p.error.empty()) return clientError(p.error);
    return p.json ? parseClientJson(p.text) : parseClientCsv(p.text);
  } catch (const std::exception& e) {
    return clientError(std::string("internal error: ") + e.what());
  } catch (...) {
    return clientError("internal error");
  }
}

// --- Client frames ------------------------------------------------------------------------------------

std::string startFrame() { return "StartFromClient:SdkLLCPP:2.0.0:TrackType1~"; }
std::string stopFrame() { return "StopFromClient~"; }
std::string startCalibrationFrame() { return "StartCalibration~"; }
std::string stopCalibrationFrame() { return "StopCalibration~"; }

std::string forceFrame(HandSide hand, Point point, float value) {
  std::string out = "force:";
  appendFloat(out, clampTo(value, 1.0f));
  out += ":0:0";  // (v, 0, 0) like the C++ and Python SDKs (§6.4)
  return endWithTarget(out, hand, point);
}

std::string stopForceFrame(HandSide hand, Point point) { return targetFrame("stopForce", hand, point); }

std::string temperatureFrame(HandSide hand, Point point, float value) {
  std::string out = "temperature:";
  appendFloat(out, std::isnan(value) ? 0.5f : clampTo(value, 1.0f));  // NaN: neutral, not coldest
  return endWithTarget(out, hand, point);
}

std::string stopTemperatureFrame(HandSide hand, Point point) { return targetFrame("stopTemperature", hand, point); }

std::string textureFrame(HandSide hand, Point point, int index, float velocity, float volume) {
  std::string out = "texture:";
  appendInt(out, index >= 0 && index <= 21 ? index : 255);
  out += ":0.5:0:";  // vx, vy: the fixed values every current SDK sends (§6.5)
  appendFloat(out, clampTo(velocity, 0.5f));
  out += ':';
  appendFloat(out, clampTo(volume, 100.0f));
  return endWithTarget(out, hand, point);
}

std::string stopTextureFrame(HandSide hand, Point point) { return targetFrame("stopTexture", hand, point); }

std::string requestFrame(std::string_view type, std::uint64_t timestampMs) {
  return jsonFrame(type, timestampMs, nullptr);
}

// --- Middleware frames --------------------------------------------------------------------------------

std::string statusFrame(const MiddlewareStatus& status, std::uint64_t timestampMs) {
  OrderedJson d;
  d["status"] = status.status;
  d["version"] = status.version;
  d["statusCode"] = status.statusCode;
  d["errorDesc"] = status.errorDesc;
  d["warningCode"] = status.warningCode;
  d["warningDesc"] = status.warningDesc;
  d["actuationsEnabled"] = status.actuationsEnabled;
  if (status.pro) {  // §7.6, in the order of its example
    d["connectionType"] = status.connectionType.empty() ? std::string("NONE") : status.connectionType;
    d["autoconnection"] = status.autoconnection;
    d["deviceSelection"] = status.deviceSelection.empty() ? std::string("PhysicalDevices") : status.deviceSelection;
    d["trackingPlayback"] = status.trackingPlayback;
    d["rawDataLog"] = status.rawDataLog;
    d["sensorOnMask"] = status.sensorOnMask;
  }
  OrderedJson devices = OrderedJson::array();
  for (const auto& dev : status.connectedDevices) {
    OrderedJson item;
    item["macAddress"] = dev.macAddress;
    item["handSide"] = handName(dev.hand);
    devices.push_back(std::move(item));
  }
  d["connectedDevices"] = std::move(devices);
  return jsonFrame(status.pro ? "WA_STATUS" : "MW_STATUS", timestampMs, &d);
}

std::string devicesFrame(const DevicesStatus& devices, std::uint64_t timestampMs) {
  OrderedJson list = OrderedJson::array();
  for (const auto& dev : devices.devices) {
    OrderedJson item;
    item["macAddress"] = dev.macAddress;
    item["handSide"] = handName(dev.hand);
    OrderedJson nodes = OrderedJson::array();
    for (const auto& n : dev.nodes) {
      OrderedJson node;
      node["id"] = std::string(wireName(n.point));
      node["connected"] = n.connected;
      if (devices.pro) {  // §7.8; the Pro has no ToF sensor, so tofFault reads true
        node["imuFault"] = false;
        node["adcFault"] = false;
        node["tofFault"] = true;
      } else {  // §7.7
        node["statusCode"] = n.statusCode;
        node["errorDesc"] = n.errorDesc;
      }
      nodes.push_back(std::move(node));
    }
    if (devices.pro) {  // §7.8, in the order of its example
      item["signalStrength"] = std::isfinite(dev.signalStrength) ? dev.signalStrength : 0.0;  // JSON has no NaN
      item["sensorsCalibDate"] = dev.sensorsCalibDate;
      OrderedJson master;
      master["batteryLevel"] = dev.batteryLevel;
      master["charging"] = dev.charging;
      master["chargeCompleted"] = false;
      master["connection"] = OrderedJson{{"bluetoothOn", dev.connection.bluetoothOn},
                                         {"bluetoothConnected", dev.connection.bluetoothConnected},
                                         {"wifiOn", dev.connection.wifiOn},
                                         {"wifiConnected", dev.connection.wifiConnected},
                                         {"usbConnected", dev.connection.usbConnected}};
      master["imuFault"] = false;
      master["adcFault"] = false;
      master["buttonPushed"] = false;
      item["master"] = std::move(master);
      item["nodes"] = std::move(nodes);
    } else {
      item["batteryLevel"] = dev.batteryLevel;
      item["charging"] = dev.charging;
      item["thimbles"] = std::move(nodes);
    }
    list.push_back(std::move(item));
  }
  OrderedJson d;
  d["devices"] = std::move(list);
  return jsonFrame(devices.pro ? "WEART_TD_PRO_STATUS" : "DEVICES_STATUS", timestampMs, &d);
}

std::string trackingG1Frame(const std::vector<HandTracking>& hands, TrackType type) {
  auto byte = [](float v) { return static_cast<long long>(std::lround(clampTo(v, 1.0f) * 255.0f)); };
  const bool type1 = type == TrackType::TrackType1;
  std::string out = type1 ? "Tracking:TrackType1" : "Tracking";
  for (const HandSide side : {HandSide::Right, HandSide::Left}) {  // right hand first (§3.1)
    const auto it = std::find_if(hands.begin(), hands.end(), [side](const HandTracking& h) { return h.hand == side; });
    std::array<long long, 4> v{};
    if (it != hands.end()) {
      auto closure = [&](Point p) { return byte(it->closure[static_cast<std::size_t>(p)]); };
      if (type1)  // index, thumb, thumb abduction, middle (§7.3.2)
        v = {closure(Point::Index), closure(Point::Thumb), byte(it->thumbAbduction), closure(Point::Middle)};
      else  // thumb, index, middle, palm (§7.3.1)
        v = {closure(Point::Thumb), closure(Point::Index), closure(Point::Middle), closure(Point::Palm)};
    }
    for (const long long x : v) {
      out += ':';
      appendInt(out, x);
    }
  }
  return out + '~';
}

std::string trackingG2Frame(const HandTracking& hand, std::uint64_t timestampMs) {
  OrderedJson d;
  d["handSide"] = handName(hand.hand);
  for (int p = 0; p < kPointCount; ++p) {
    const bool thumb = static_cast<Point>(p) == Point::Thumb;
    OrderedJson node;
    node["closure"] = wireDouble(clampTo(hand.closure[static_cast<std::size_t>(p)], 1.0f));
    node["abduction"] = thumb ? wireDouble(clampTo(hand.thumbAbduction, 1.0f)) : 0.0;
    d[kPointKeys[p]] = std::move(node);
  }
  if (hand.wristQuaternion) {
    const auto& q = *hand.wristQuaternion;
    d["wrist"]["quaternion"] =
        OrderedJson{{"x", wireDouble(q[0])}, {"y", wireDouble(q[1])}, {"z", wireDouble(q[2])}, {"w", wireDouble(q[3])}};
  }
  return jsonFrame("TRACKING_BENDING_G2", timestampMs, &d);
}

std::string rawDataFrame(HandSide hand, const std::vector<RawSample>& samples, bool pro, std::uint64_t timestampMs) {
  auto vector = [](const std::array<float, 3>& v) {
    return OrderedJson{{"x", wireDouble(v[0])}, {"y", wireDouble(v[1])}, {"z", wireDouble(v[2])}};
  };
  OrderedJson d;
  d["handSide"] = handName(hand);
  for (const RawSample& sample : samples) {
    OrderedJson sensor;
    sensor["accelerometer"] = vector(sample.accelerometer);
    sensor["gyroscope"] = vector(sample.gyroscope);
    if (!pro) sensor["timeOfFlight"] = OrderedJson{{"distance", sample.distance}};
    d[kPointKeys[static_cast<std::size_t>(sample.point)]] = std::move(sensor);
  }
  return jsonFrame(pro ? "RAW_DATA_TD_PRO" : "RAW_DATA", timestampMs, &d);
}

std::string calibrationStatusFrame(HandSide hand, int status) {
  std::string out = hand == HandSide::Right ? "CalibrationStatus:1:" : "CalibrationStatus:0:";
  appendInt(out, status);
  return out + '~';
}

std::string calibrationResultFrame(HandSide hand, bool success) {
  return std::string("CalibrationResult:") + (hand == HandSide::Right ? '1' : '0') + (success ? ":0~" : ":1~");
}

}  // namespace vrd::weart
