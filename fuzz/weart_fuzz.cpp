// libFuzzer target for the WEART wire protocol (weart_protocol.h). The input is a byte stream from a
// middleware or a client: it is cut into frames by a FrameSplitter fed in chunks whose sizes come
// from the input itself, and every frame, and the whole input as one frame, goes through both
// parsers. Besides crashes, sanitizer reports and leaks, a broken invariant is a finding
// (__builtin_trap): a parser answering both or neither of a result and an error; the frames, drops
// or tail depending on how the stream was chunked; the splitter holding more than its cap; or an
// accepted frame that, written back by our formatters, does not parse to the same thing.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "vrdeform/devices/weart_protocol.h"

namespace {

using namespace vrd::weart;

constexpr std::size_t kCap = 256;  // small, so that over-long frames are common

void require(bool ok) {
  if (!ok) __builtin_trap();
}

float written(float v) { return std::fabs(v) >= 1e-6f ? v : 0.0f; }  // the client formatter's flush to 0
std::size_t at(Point p) { return static_cast<std::size_t>(p); }

void clientReadsBack(const ClientCommand& c) {
  using Kind = ClientCommand::Kind;
  std::string frame;
  switch (c.kind) {
    case Kind::Force:
      frame = forceFrame(c.hand, c.point, c.value);
      break;
    case Kind::Temperature:
      frame = temperatureFrame(c.hand, c.point, c.value);
      break;
    case Kind::Texture:
      frame = textureFrame(c.hand, c.point, c.textureIndex, c.value, c.volume);
      break;
    case Kind::StopForce:
      frame = stopForceFrame(c.hand, c.point);
      break;
    case Kind::StopTemperature:
      frame = stopTemperatureFrame(c.hand, c.point);
      break;
    case Kind::StopTexture:
      frame = stopTextureFrame(c.hand, c.point);
      break;
    case Kind::Request:
      frame = requestFrame(c.text, c.timestampMs);
      break;
    default:
      return;
  }
  const ParsedClient back = parseClientFrame(frame);
  require(back.command.has_value());
  const ClientCommand& b = *back.command;
  require(b.kind == c.kind && b.text == c.text && b.timestampMs == c.timestampMs);
  if (c.kind == Kind::Request) return;
  require(b.hand == c.hand && b.point == c.point && b.value == written(c.value) && b.volume == written(c.volume) &&
          b.textureIndex == c.textureIndex);
}

void middlewareReadsBack(const MiddlewareMessage& m, std::uint64_t ts) {
  if (const auto* s = std::get_if<MiddlewareStatus>(&m)) {
    const ParsedMiddleware back = parseMiddlewareFrame(statusFrame(*s, ts));
    require(back.message && back.timestampMs == ts);
    const auto& b = std::get<MiddlewareStatus>(*back.message);
    require(b.pro == s->pro && b.status == s->status && b.version == s->version && b.statusCode == s->statusCode &&
            b.errorDesc == s->errorDesc && b.warningCode == s->warningCode && b.warningDesc == s->warningDesc &&
            b.actuationsEnabled == s->actuationsEnabled && b.connectedDevices.size() == s->connectedDevices.size());
    for (std::size_t i = 0; i < b.connectedDevices.size(); ++i)
      require(b.connectedDevices[i].macAddress == s->connectedDevices[i].macAddress &&
              b.connectedDevices[i].hand == s->connectedDevices[i].hand);
  } else if (const auto* d = std::get_if<DevicesStatus>(&m)) {
    const ParsedMiddleware back = parseMiddlewareFrame(devicesFrame(*d, ts));
    require(back.message.has_value());
    const auto& b = std::get<DevicesStatus>(*back.message);
    require(b.pro == d->pro && b.devices.size() == d->devices.size());
    for (std::size_t i = 0; i < b.devices.size(); ++i)
      require(b.devices[i].macAddress == d->devices[i].macAddress && b.devices[i].hand == d->devices[i].hand &&
              b.devices[i].batteryLevel == d->devices[i].batteryLevel &&
              b.devices[i].nodes.size() == d->devices[i].nodes.size() &&
              (!d->pro || (b.devices[i].signalStrength == d->devices[i].signalStrength &&
                           b.devices[i].sensorsCalibDate == d->devices[i].sensorsCalibDate &&
                           b.devices[i].connection.bluetoothConnected == d->devices[i].connection.bluetoothConnected)));
  } else if (const auto* t = std::get_if<Tracking>(&m)) {
    if (t->hands.size() == 1) {  // Pro: one hand per frame
      const ParsedMiddleware back = parseMiddlewareFrame(trackingG2Frame(t->hands[0], ts));
      require(back.message.has_value());
      const HandTracking& b = std::get<Tracking>(*back.message).hands.at(0);
      require(b.hand == t->hands[0].hand && b.thumbAbduction == written(t->hands[0].thumbAbduction));
      for (std::size_t p = 0; p < b.closure.size(); ++p) require(b.closure[p] == written(t->hands[0].closure[p]));
      require(b.wristQuaternion.has_value() == t->hands[0].wristQuaternion.has_value());
    } else {  // G1: both hands; TrackType1 carries index, thumb, thumb abduction and middle
      const ParsedMiddleware back = parseMiddlewareFrame(trackingG1Frame(t->hands));
      require(back.message.has_value());
      const auto& b = std::get<Tracking>(*back.message).hands;
      require(b.size() == 2 && t->hands.size() == 2);
      auto same = [](float now, float before) { return now == (std::isnan(before) ? 0.0f : before); };
      for (std::size_t h = 0; h < 2; ++h) {
        require(b[h].hand == t->hands[h].hand && same(b[h].thumbAbduction, t->hands[h].thumbAbduction));
        for (const Point p : {Point::Thumb, Point::Index, Point::Middle})
          require(same(b[h].closure[at(p)], t->hands[h].closure[at(p)]));
      }
    }
  } else if (const auto* c = std::get_if<CalibrationStatus>(&m)) {
    const ParsedMiddleware back = parseMiddlewareFrame(calibrationStatusFrame(c->hand, c->status));
    require(back.message.has_value());
    const auto& b = std::get<CalibrationStatus>(*back.message);
    require(b.hand == c->hand && b.status == c->status);
  } else if (const auto* r = std::get_if<CalibrationResult>(&m)) {
    const ParsedMiddleware back = parseMiddlewareFrame(calibrationResultFrame(r->hand, r->success));
    require(back.message.has_value());
    const auto& b = std::get<CalibrationResult>(*back.message);
    require(b.hand == r->hand && b.success == r->success);
  }
}

void check(std::string_view frame) {
  const ParsedMiddleware mw = parseMiddlewareFrame(frame);
  require(mw.message.has_value() != !mw.error.empty());
  if (mw.message) middlewareReadsBack(*mw.message, mw.timestampMs);
  const ParsedClient client = parseClientFrame(frame);
  require(client.command.has_value() != !client.error.empty());
  if (client.command) clientReadsBack(*client.command);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  check(input);

  FrameSplitter whole(kCap);
  std::vector<std::string> wholeFrames;
  whole.feed(input, wholeFrames);

  FrameSplitter chunked(kCap);
  std::vector<std::string> chunkedFrames;
  for (std::size_t pos = 0, i = 0; pos < size; ++i) {
    // 0-63 bytes, from the input's own bytes; empty feeds included.
    const std::size_t n = std::min<std::size_t>((data[i % size] * 31u + i) % 64u, size - pos);
    chunked.feed(input.substr(pos, n), chunkedFrames);
    require(chunked.buffered() <= kCap);
    pos += n;
  }
  require(wholeFrames == chunkedFrames && whole.dropped() == chunked.dropped() &&
          whole.buffered() == chunked.buffered());
  for (const std::string& frame : wholeFrames) {
    require(!frame.empty() && frame.size() <= kCap && frame.find('~') == std::string::npos);
    check(frame);
  }
  return 0;
}
