#include "vrdeform/testing/fake_middleware.h"

#include "vrdeform/core/posix_fd.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>
#include <utility>

#include "vrdeform/devices/weart_client.h"  // pointOf
#include "vrdeform/error.h"

namespace vrd::weart {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

constexpr milliseconds kIdlePoll{5};
constexpr milliseconds kWriteTimeout{1000};

std::uint64_t unixMs() {
  return std::uint64_t(
      std::chrono::duration_cast<milliseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

std::string_view trim(std::string_view s) {
  auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; };
  while (!s.empty() && space(s.front())) s.remove_prefix(1);
  while (!s.empty() && space(s.back())) s.remove_suffix(1);
  return s;
}

std::size_t handIndex(HandSide hand) { return hand == HandSide::Left ? 0 : 1; }

std::string macOf(HandSide hand) { return hand == HandSide::Left ? "FA:KE:00:00:00:01" : "FA:KE:00:00:00:02"; }

}  // namespace

// --- TrackingScript ------------------------------------------------------------------------------

TrackingScript TrackingScript::parse(std::string_view text, std::string_view name) {
  TrackingScript script;
  std::size_t lineNumber = 0;
  while (!text.empty()) {
    ++lineNumber;
    const std::size_t end = text.find('\n');
    std::string_view line = text.substr(0, end);
    text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    line = trim(line);
    if (line.empty()) continue;
    auto fail = [&](const std::string& why) {
      return Error(fmt::format("{}:{}: {} (expected: t thumb index middle [ring little])", name, lineNumber, why));
    };
    std::vector<double> values;
    while (!line.empty()) {
      std::size_t n = 0;
      while (n < line.size() && line[n] != ' ' && line[n] != '\t') ++n;
      const std::string_view token = line.substr(0, n);
      double v = 0;
      const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
      if (ec != std::errc() || ptr != token.data() + token.size() || !std::isfinite(v))
        throw fail("'" + std::string(token) + "' is not a number");
      values.push_back(v);
      line = trim(line.substr(n));
    }
    if (values.size() != 4 && values.size() != 6) throw fail(fmt::format("{} numbers", values.size()));
    Key key;
    key.time = values[0];
    if (key.time < 0) throw fail("negative time");
    if (!script.keys_.empty() && key.time <= script.keys_.back().time) throw fail("times must increase");
    for (std::size_t f = 0; f < std::size_t(kFingerCount); ++f) {
      const double c = f + 1 < values.size() ? values[f + 1] : values[3];  // ring, little: as middle
      if (c < 0 || c > 1) throw fail(fmt::format("closure {} is outside [0, 1]", c));
      key.closure[f] = float(c);
    }
    script.keys_.push_back(key);
  }
  if (script.keys_.empty()) throw Error(fmt::format("{}: no keyframes", name));
  return script;
}

TrackingScript TrackingScript::load(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open tracking script " + path.string());
  std::ostringstream text;
  text << in.rdbuf();
  return parse(text.str(), path.string());
}

std::array<float, kFingerCount> TrackingScript::at(double seconds) const {
  if (keys_.empty()) return {};
  if (!(seconds > keys_.front().time)) return keys_.front().closure;
  if (seconds >= keys_.back().time) return keys_.back().closure;
  const auto next =
      std::upper_bound(keys_.begin(), keys_.end(), seconds, [](double t, const Key& k) { return t < k.time; });
  const Key& b = *next;
  const Key& a = *(next - 1);
  const float w = float((seconds - a.time) / (b.time - a.time));
  std::array<float, kFingerCount> c{};
  for (std::size_t f = 0; f < c.size(); ++f) c[f] = a.closure[f] + w * (b.closure[f] - a.closure[f]);
  return c;
}

TrackingSource TrackingScript::source() const {
  return [script = *this](double seconds) { return script.at(seconds); };
}

// --- describe ------------------------------------------------------------------------------------

std::string describe(const ClientCommand& c) {
  const std::string_view hand = wireName(c.hand), point = wireName(c.point);
  using K = ClientCommand::Kind;
  switch (c.kind) {
    case K::Start:
      return c.text.empty() ? "StartFromClient" : "StartFromClient " + c.text;
    case K::Stop:
      return "StopFromClient";
    case K::StartCalibration:
      return "StartCalibration";
    case K::StopCalibration:
      return "StopCalibration";
    case K::ResetCalibration:
      return "ResetCalibration";
    case K::Force:
      return fmt::format("force {} {} {}", hand, point, c.value);
    case K::StopForce:
      return fmt::format("stopForce {} {}", hand, point);
    case K::Temperature:
      return fmt::format("temperature {} {} {}", hand, point, c.value);
    case K::StopTemperature:
      return fmt::format("stopTemperature {} {}", hand, point);
    case K::Texture:
      return fmt::format("texture {} {} {} {} {}", hand, point, c.textureIndex, c.value, c.volume);
    case K::StopTexture:
      return fmt::format("stopTexture {} {}", hand, point);
    case K::Request:
      return c.text;
  }
  return "?";
}

// --- FakeMiddleware ------------------------------------------------------------------------------

struct FakeMiddleware::Impl {
  explicit Impl(FakeMiddlewareSettings s) : settings(std::move(s)), tracking(settings.tracking) {}

  const FakeMiddlewareSettings settings;
  Fd listener;
  std::uint16_t port = 0;
  WakePipe wakePipe;
  std::atomic<bool> stopping{false};
  std::atomic<bool> stopped{false};
  std::thread thread;

  // ---- shared with the test / program thread (under `mutex`) ----
  mutable std::mutex mutex;
  std::vector<ReceivedCommand> commands;
  std::array<std::array<Latched, kPointCount>, 2> latched{};
  std::string status = "IDLE";
  int connections = 0;
  bool connected = false;
  std::uint64_t malformed = 0;
  std::uint64_t trackingSent = 0;
  bool rawData = false;
  TrackingSource tracking;
  int startError = 0;
  milliseconds readDelay{0};
  bool dropRequested = false;
  struct Write {
    std::string bytes;
    std::size_t splitAt = 0;  // 0: in one go
  };
  std::vector<Write> pendingWrites;

  // ---- the fake's thread only ----
  Fd client;
  int connection = 0;
  FrameSplitter splitter;
  bool streaming = false;
  Clock::time_point sessionStart{}, nextTick{}, nextStatus{};
  std::optional<Clock::time_point> calibrationDue;
  TrackType trackType = TrackType::TrackType1;
  int statusCode = 0;  // of the last status pushed, repeated until the status changes
  std::string errorDesc;

  void wake() const { wakePipe.notify(); }
  void note(std::string_view text) const {
    if (settings.onNote) settings.onNote(text);
  }

  void run() noexcept;
  void accept();
  void closeClient(std::string_view why);
  bool write(std::string_view bytes);
  void hooks();
  void readClient();
  void onCommand(const ClientCommand& c);
  void tick();
  std::vector<Point> nodes() const;
  MiddlewareStatus makeStatus() const;
  DevicesStatus makeDevices() const;
  std::string rawDataOf(const HandTracking& hand) const;
  /// A status change: remembered (repeated by later pushes and answers) and pushed.
  bool pushStatus(const std::string& s, int code = 0, std::string desc = {}) {
    {
      std::lock_guard lock(mutex);
      status = s;
    }
    statusCode = code;
    errorDesc = std::move(desc);
    return write(statusFrame(makeStatus(), unixMs()));
  }
  /// The status and the device status, unasked.
  bool pushAll() {
    nextStatus = Clock::now() + settings.statusPeriod;
    return write(statusFrame(makeStatus(), unixMs()) + devicesFrame(makeDevices(), unixMs()));
  }
};

/// The nodes of each glove: the G1's three thimbles (its control unit, PALM, is not listed as one,
/// §7.7), every point of a Pro (§7.8).
std::vector<Point> FakeMiddleware::Impl::nodes() const {
  if (settings.pro) return {Point::Thumb, Point::Index, Point::Middle, Point::Annular, Point::Pinky, Point::Palm};
  return {Point::Thumb, Point::Index, Point::Middle};
}

// The Pro gloves are on BLE: WA_STATUS's connectionType and each master's connection say so alike.
MiddlewareStatus FakeMiddleware::Impl::makeStatus() const {
  MiddlewareStatus m;
  m.pro = settings.pro;
  {
    std::lock_guard lock(mutex);
    m.status = status;
  }
  m.version = settings.pro ? "2.0.0" : "1.4.0";
  m.statusCode = statusCode;
  m.errorDesc = errorDesc;
  m.actuationsEnabled = true;
  for (HandSide hand : settings.hands) m.connectedDevices.push_back({macOf(hand), hand});
  if (settings.pro) {
    m.connectionType = settings.hands.empty() ? "NONE" : "BLE";
    m.autoconnection = true;
    m.deviceSelection = "PhysicalDevices";
  }
  return m;
}

DevicesStatus FakeMiddleware::Impl::makeDevices() const {
  DevicesStatus d;
  d.pro = settings.pro;
  for (HandSide hand : settings.hands) {
    DevicesStatus::Device device;
    device.macAddress = macOf(hand);
    device.hand = hand;
    device.batteryLevel = 85;
    for (Point p : nodes()) device.nodes.push_back({p, true, 0, ""});
    if (settings.pro) {
      device.signalStrength = -55.0;
      device.sensorsCalibDate = "2026-01-01T00:00:00Z";
      device.connection.bluetoothOn = true;
      device.connection.bluetoothConnected = true;
    }
    d.devices.push_back(std::move(device));
  }
  return d;
}

/// RAW_DATA(_TD_PRO) of one hand: a sample from every node, and from the G1's control unit (§7.9);
/// at rest under gravity, the time of flight following the finger's closure.
std::string FakeMiddleware::Impl::rawDataOf(const HandTracking& hand) const {
  std::vector<Point> points = nodes();
  if (!settings.pro) points.push_back(Point::Palm);
  std::vector<RawSample> samples;
  for (Point p : points) {
    RawSample s;
    s.point = p;
    s.accelerometer = {0.0f, -1.0f, 0.0f};
    if (p != Point::Palm) s.distance = int(std::lround(60.0f - 50.0f * hand.closure[std::size_t(p)]));
    samples.push_back(s);
  }
  return rawDataFrame(hand.hand, samples, settings.pro, unixMs());
}

void FakeMiddleware::Impl::run() noexcept {
  try {
    while (!stopping.load()) {
      if (!client) {
        pollfd p[2] = {{listener.get(), POLLIN, 0}, {wakePipe.fd(), POLLIN, 0}};
        ::poll(p, 2, int(kIdlePoll.count()));
        wakePipe.drain();
        hooks();  // nobody to act on: discards
        if (p[0].revents & POLLIN) accept();
        continue;
      }
      Clock::time_point next = Clock::now() + kIdlePoll;
      if (streaming) next = std::min(next, nextTick);
      if (settings.statusPeriod.count() > 0) next = std::min(next, nextStatus);
      if (calibrationDue) next = std::min(next, *calibrationDue);
      pollfd p[2] = {{client.get(), POLLIN, 0}, {wakePipe.fd(), POLLIN, 0}};
      ::poll(p, 2, pollMs(next - Clock::now()));
      wakePipe.drain();
      hooks();
      if (client && (p[0].revents & (POLLIN | POLLHUP | POLLERR))) readClient();
      if (client) tick();
    }
  } catch (const std::exception& e) {
    note(std::string("fake middleware error: ") + e.what());
  }
  closeClient("fake middleware stopped");
}

void FakeMiddleware::Impl::accept() {
  Fd fd(::accept4(listener.get(), nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC));
  if (!fd) return;
  const int one = 1;
  ::setsockopt(fd.get(), IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  client = std::move(fd);
  splitter.reset();
  streaming = false;
  calibrationDue.reset();
  statusCode = 0;
  errorDesc.clear();
  {
    std::lock_guard lock(mutex);
    connection = ++connections;
    connected = true;
    for (auto& hand : latched) hand.fill(Latched{});
    status = "IDLE";
    rawData = false;
  }
  note(fmt::format("client {} connected", connection));
  pushAll();
}

void FakeMiddleware::Impl::closeClient(std::string_view why) {
  if (!client) return;
  client.reset();
  streaming = false;
  calibrationDue.reset();
  {
    std::lock_guard lock(mutex);
    connected = false;
    rawData = false;
    status = "IDLE";
  }
  note(fmt::format("client {} gone: {}", connection, why));
}

bool FakeMiddleware::Impl::write(std::string_view bytes) {
  const Clock::time_point deadline = Clock::now() + kWriteTimeout;
  while (client && !bytes.empty()) {
    const ssize_t n = ::send(client.get(), bytes.data(), bytes.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      bytes.remove_prefix(std::size_t(n));
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK) && Clock::now() < deadline) {
      // A client that does not read must not hold up stop(). Drained before the check: stop() sets
      // `stopping` before it wakes. The other wakes are for hooks(), which run every loop anyway.
      pollfd p[2] = {{client.get(), POLLOUT, 0}, {wakePipe.fd(), POLLIN, 0}};
      ::poll(p, 2, pollMs(deadline - Clock::now()));
      wakePipe.drain();
      if (stopping.load()) return false;  // run() closes the client on its way out
      continue;
    }
    closeClient(n < 0 ? std::string("send: ") + std::strerror(errno) : std::string("send failed"));
    return false;
  }
  return bool(client);
}

void FakeMiddleware::Impl::hooks() {
  bool drop = false;
  std::vector<Write> writes;
  {
    std::lock_guard lock(mutex);
    drop = std::exchange(dropRequested, false);
    writes.swap(pendingWrites);
  }
  if (!client) return;
  if (drop) {
    closeClient("dropped (test hook)");
    return;
  }
  for (const Write& w : writes) {
    if (w.splitAt == 0 || w.splitAt >= w.bytes.size()) {
      if (!write(w.bytes)) return;
      continue;
    }
    if (!write(std::string_view(w.bytes).substr(0, w.splitAt))) return;
    std::this_thread::sleep_for(milliseconds(10));
    if (!write(std::string_view(w.bytes).substr(w.splitAt))) return;
  }
}

void FakeMiddleware::Impl::readClient() {
  milliseconds delay{0};
  {
    std::lock_guard lock(mutex);
    delay = readDelay;
  }
  if (delay.count() > 0) std::this_thread::sleep_for(delay);
  char buffer[65536];
  // A slow reader also reads little at a time, so the client's socket fills up.
  const std::size_t chunk = delay.count() > 0 ? 256 : sizeof buffer;
  const ssize_t n = ::recv(client.get(), buffer, chunk, MSG_DONTWAIT);
  if (n == 0) {
    closeClient("closed by the client");
    return;
  }
  if (n < 0) {
    if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
      closeClient(std::string("recv: ") + std::strerror(errno));
    return;
  }
  std::vector<std::string> frames;
  splitter.feed(std::string_view(buffer, std::size_t(n)), frames);
  for (const std::string& frame : frames) {
    if (!client) return;
    const ParsedClient parsed = parseClientFrame(frame);
    if (!parsed.command) {
      {
        std::lock_guard lock(mutex);
        ++malformed;
      }
      note("malformed client frame '" + frame + "': " + parsed.error);
      continue;
    }
    onCommand(*parsed.command);
  }
}

void FakeMiddleware::Impl::onCommand(const ClientCommand& c) {
  using K = ClientCommand::Kind;
  const ReceivedCommand received{Clock::now(), connection, c};
  int error = 0;
  {
    std::lock_guard lock(mutex);
    commands.push_back(received);
    Latched& l = latched[handIndex(c.hand)][std::size_t(c.point)];
    switch (c.kind) {
      case K::Force:
        l.force = c.value;
        break;
      case K::StopForce:
        l.force = 0.0f;
        break;
      case K::Temperature:
        l.temperature = c.value;
        break;
      case K::StopTemperature:
        l.temperature.reset();
        break;
      case K::Texture:
        l.texture = c.textureIndex;
        break;
      case K::StopTexture:
        l.texture.reset();
        break;
      case K::Request:
        if (c.text == "RAW_DATA_ON") rawData = true;
        if (c.text == "RAW_DATA_OFF") rawData = false;
        break;
      default:
        break;
    }
    error = startError;
  }
  if (settings.onCommand) settings.onCommand(received);

  switch (c.kind) {
    case K::Start:
      if (error != 0) {
        pushStatus("IDLE", error, fmt::format("cannot start (fake error {})", error));
        return;
      }
      if (!pushStatus("STARTING") || !pushStatus("RUNNING")) return;
      trackType = c.text.empty() ? TrackType::Default : TrackType::TrackType1;  // §6.1: bare start, DEFAULT
      streaming = true;
      sessionStart = nextTick = Clock::now();
      return;
    case K::Stop:
      streaming = false;
      calibrationDue.reset();
      {
        std::lock_guard lock(mutex);
        rawData = false;
      }
      if (pushStatus("STOPPING")) pushStatus("IDLE");
      return;
    case K::StartCalibration:
      if (!streaming || calibrationDue) return;
      if (!pushStatus("CALIBRATION")) return;
      for (HandSide hand : settings.hands)
        if (!write(calibrationStatusFrame(hand, 1))) return;
      calibrationDue = Clock::now() + settings.calibrationTime;
      return;
    case K::Request:
      if (c.text == "MW_GET_STATUS" || c.text == "WA_GET_STATUS") {
        write(statusFrame(makeStatus(), unixMs()));
      } else if (c.text == "DEVICES_GET_STATUS") {
        write(devicesFrame(makeDevices(), unixMs()));
      }
      return;
    default:
      return;  // haptics: latched above, no reply (§11)
  }
}

void FakeMiddleware::Impl::tick() {
  const Clock::time_point now = Clock::now();
  if (settings.statusPeriod.count() > 0 && now >= nextStatus && !pushAll()) return;
  if (calibrationDue && now >= *calibrationDue) {
    calibrationDue.reset();
    for (HandSide hand : settings.hands) {
      if (!write(calibrationStatusFrame(hand, 2))) return;
      if (!write(calibrationResultFrame(hand, settings.calibrationSucceeds))) return;
    }
    if (!pushStatus("RUNNING")) return;
  }
  if (!streaming || now < nextTick) return;
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / std::max(settings.trackingHz, 0.1)));
  nextTick += period;
  if (nextTick < now) nextTick = now + period;  // late (a slow reader): no burst

  TrackingSource source;
  bool raw = false;
  {
    std::lock_guard lock(mutex);
    source = tracking;
    raw = rawData;
  }
  const double t = std::chrono::duration<double>(now - sessionStart).count();
  const std::array<float, kFingerCount> fingers = source ? source(t) : std::array<float, kFingerCount>{};
  std::vector<HandTracking> hands;
  for (HandSide hand : settings.hands) {
    HandTracking h;
    h.hand = hand;
    h.closure.fill(0.0f);
    for (int f = 0; f < kFingerCount; ++f) {
      const float c = fingers[std::size_t(f)];
      h.closure[std::size_t(pointOf(Finger(f)))] = std::isfinite(c) ? std::clamp(c, 0.0f, 1.0f) : 0.0f;
    }
    h.thumbAbduction = 0.5f;
    if (settings.pro) h.wristQuaternion = std::array<float, 4>{0.0f, 0.0f, 0.0f, 1.0f};
    hands.push_back(h);
  }
  std::string frames;
  if (settings.pro) {
    for (const HandTracking& h : hands) frames += trackingG2Frame(h, unixMs());
  } else {
    frames += trackingG1Frame(hands, trackType);
  }
  if (raw)
    for (const HandTracking& h : hands) frames += rawDataOf(h);
  if (write(frames)) {
    std::lock_guard lock(mutex);
    ++trackingSent;
  }
}

FakeMiddleware::FakeMiddleware(FakeMiddlewareSettings settings) : impl_(std::make_unique<Impl>(std::move(settings))) {
  Impl& m = *impl_;
  m.listener.reset(::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
  if (!m.listener) throw Error(std::string("fake middleware: socket: ") + std::strerror(errno));
  const int one = 1;
  ::setsockopt(m.listener.get(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (m.settings.receiveBuffer > 0)
    ::setsockopt(m.listener.get(), SOL_SOCKET, SO_RCVBUF, &m.settings.receiveBuffer, sizeof m.settings.receiveBuffer);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(m.settings.port);
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::bind(m.listener.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0)
    throw Error(
        fmt::format("fake middleware: cannot listen on 127.0.0.1:{}: {}", m.settings.port, std::strerror(errno)));
  if (::listen(m.listener.get(), 4) != 0) throw Error(std::string("fake middleware: listen: ") + std::strerror(errno));
  socklen_t length = sizeof address;
  ::getsockname(m.listener.get(), reinterpret_cast<sockaddr*>(&address), &length);
  m.port = ntohs(address.sin_port);
}

FakeMiddleware::~FakeMiddleware() { stop(); }

void FakeMiddleware::start() {
  if (impl_->stopped.load()) throw Error("fake middleware: start() after stop()");
  if (impl_->thread.joinable()) return;
  Impl* impl = impl_.get();
  impl_->thread = std::thread([impl] { impl->run(); });
}

void FakeMiddleware::stop() noexcept {
  if (impl_->stopped.exchange(true)) return;
  impl_->stopping.store(true);
  impl_->wake();
  if (impl_->thread.joinable()) impl_->thread.join();
  impl_->client.reset();
  impl_->listener.reset();
}

std::uint16_t FakeMiddleware::port() const { return impl_->port; }

std::vector<ReceivedCommand> FakeMiddleware::commands() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->commands;
}

Latched FakeMiddleware::latched(HandSide hand, Point point) const {
  std::lock_guard lock(impl_->mutex);
  return impl_->latched[handIndex(hand)][std::size_t(point)];
}

std::string FakeMiddleware::status() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->status;
}

int FakeMiddleware::connections() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->connections;
}

bool FakeMiddleware::clientConnected() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->connected;
}

std::uint64_t FakeMiddleware::malformedFrames() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->malformed;
}

std::uint64_t FakeMiddleware::trackingFramesSent() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->trackingSent;
}

bool FakeMiddleware::rawDataOn() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->rawData;
}

void FakeMiddleware::setTracking(TrackingSource source) {
  std::lock_guard lock(impl_->mutex);
  impl_->tracking = std::move(source);
}

void FakeMiddleware::dropClient() {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->dropRequested = true;
  }
  impl_->wake();
}

void FakeMiddleware::sendRaw(std::string bytes) {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->pendingWrites.push_back({std::move(bytes), 0});
  }
  impl_->wake();
}

void FakeMiddleware::sendSplit(std::string bytes, std::size_t at) {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->pendingWrites.push_back({std::move(bytes), at});
  }
  impl_->wake();
}

void FakeMiddleware::setStartError(int statusCode) {
  std::lock_guard lock(impl_->mutex);
  impl_->startError = statusCode;
}

void FakeMiddleware::setReadDelay(std::chrono::milliseconds d) {
  std::lock_guard lock(impl_->mutex);
  impl_->readDelay = std::max(d, milliseconds(0));
}

void FakeMiddleware::sendExit() { sendRaw("exit~"); }

void FakeMiddleware::sendDisconnect() { sendRaw("disconnect~"); }

}  // namespace vrd::weart
