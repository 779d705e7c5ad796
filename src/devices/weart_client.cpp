#include "vrdeform/devices/weart_client.h"

#include "endpoint.h"
#include "vrdeform/core/posix_fd.h"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <deque>
#include <mutex>
#include <set>
#include <thread>
#include <utility>

#include "vrdeform/error.h"

namespace vrd::weart {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

constexpr milliseconds kPollInterval{2};       // how often the I/O thread checks its timers and watchdog
constexpr milliseconds kCloseFlushTime{1000};  // shutdown: time to write the stop frames
constexpr milliseconds kCloseDrainTime{1000};  // shutdown: time for the middleware to close
constexpr std::chrono::seconds kCalibrationTimeout{30};
constexpr std::size_t kMaxEvents = 256;
constexpr std::size_t kMaxPending = 1 << 20;  // unsent bytes before the connection counts as stuck
constexpr std::size_t kReadChunk = 16384;

std::uint64_t unixMs() {
  return std::uint64_t(
      std::chrono::duration_cast<milliseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

// Why a session ended.
enum class Ending { Stopping, PeerClosed, Failed, Exit };

}  // namespace

// --- free functions -----------------------------------------------------------------------------

ClientSettings parseEndpoint(std::string_view endpoint, ClientSettings base) {
  std::string why;
  const std::optional<Endpoint> e = splitEndpoint(endpoint, why);
  if (!e)
    throw Error("WEART endpoint '" + std::string(endpoint) + "': " + why +
                " (expected HOST:PORT, HOST, :PORT or [IPv6]:PORT)");
  if (!e->host.empty()) base.host = e->host;
  if (e->port) base.port = *e->port;
  return base;
}

Point pointOf(Finger finger) {
  switch (finger) {
    case Finger::Thumb:
      return Point::Thumb;
    case Finger::Index:
      return Point::Index;
    case Finger::Middle:
      return Point::Middle;
    case Finger::Ring:
      return Point::Annular;
    case Finger::Little:
      return Point::Pinky;
  }
  return Point::Thumb;
}

std::string_view toString(State state) {
  switch (state) {
    case State::Disconnected:
      return "disconnected";
    case State::Connecting:
      return "connecting";
    case State::Idle:
      return "idle";
    case State::Starting:
      return "starting";
    case State::Running:
      return "running";
    case State::Calibrating:
      return "calibrating";
    case State::Stopping:
      return "stopping";
  }
  return "?";
}

// --- the client ----------------------------------------------------------------------------------

struct Client::Impl {
  explicit Impl(ClientSettings s) : settings(std::move(s)) {
    for (Point p : settings.thimbles) isThimble[std::size_t(p)] = true;
  }

  const ClientSettings settings;
  std::array<bool, kPointCount> isThimble{};

  // ---- Written by the simulation, read by the I/O thread (under `desiredMutex`). ----
  struct Desired {
    std::array<float, kPointCount> force{};
    std::array<std::optional<float>, kPointCount> temperature{};
    std::array<std::optional<Texture>, kPointCount> texture{};
    bool rawData = false;
    bool published = false;  // publishForces was called at least once
    Clock::time_point lastPublish{};
  };
  mutable std::mutex desiredMutex;
  Desired desired;

  // ---- Written by the I/O thread, read by anyone (under `infoMutex`, or atomic). ----
  mutable std::mutex infoMutex;
  std::optional<std::array<float, kFingerCount>> closures;
  std::optional<MiddlewareStatus> status;
  std::optional<DevicesStatus> devices;
  std::deque<Event> events;
  std::atomic<State> state{State::Disconnected};
  std::atomic<std::uint64_t> framesSent{0}, framesReceived{0}, malformedFrames{0}, reconnects{0}, watchdogTrips{0};

  // ---- Owner side. ----
  std::atomic<bool> stopRequested{false};
  std::atomic<bool> shutDown{false};
  WakePipe wake;
  std::thread thread;

  // ---- The I/O thread's own state (nothing else touches it). ----
  Fd socket;
  FrameSplitter splitter;
  std::size_t splitterDropped = 0;
  std::string outbox;              // frames not yet taken by the kernel
  std::set<std::string> problems;  // reported and not yet resolved: each reported once
  bool everConnected = false;
  bool calibrated = false;                   // calibration ran (once per client)
  Clock::duration retry{};                   // current reconnect back-off
  Clock::duration startRetry{};              // current back-off for restarting a refused session
  std::optional<Clock::time_point> startAt;  // when to (re)send StartFromClient
  Clock::time_point startSentAt{};
  std::optional<Clock::time_point> calibrationDeadline;
  bool watchdogTripped = false;
  // What the glove has, as the last frame sent per point (nullopt: unknown, so the next sync sends).
  std::array<std::optional<std::string>, kPointCount> sentForce, sentTemperature, sentTexture;
  bool sentRawData = false;

  // ---- shared helpers ----
  void event(std::string message, bool error) {
    std::lock_guard lock(infoMutex);
    events.push_back({Clock::now(), std::move(message), error});
    while (events.size() > kMaxEvents) events.pop_front();
  }
  // A problem is reported once, until resolve() clears it.
  void problem(const std::string& key, std::string message, bool error = true) {
    if (problems.insert(key).second) event(std::move(message), error);
  }
  void resolve(std::string_view prefix) {
    for (auto it = problems.begin(); it != problems.end();)
      it = std::string_view(*it).starts_with(prefix) ? problems.erase(it) : std::next(it);
  }
  void setState(State s) { state.store(s); }
  std::string endpoint() const {
    const bool v6 = settings.host.find(':') != std::string::npos;
    return (v6 ? "[" + settings.host + "]" : settings.host) + ":" + std::to_string(settings.port);
  }

  // ---- the I/O thread ----
  void run() noexcept;
  bool waitOrStop(Clock::duration d);
  Fd connect(std::string& why);
  Ending session();
  void closeGracefully(bool releaseAll);
  void enqueue(std::string frame) {
    outbox += frame;
    framesSent.fetch_add(1, std::memory_order_relaxed);
  }
  bool flush(std::string& why);
  bool receive(std::vector<std::string>& frames, bool& closed, std::string& why);
  std::optional<Ending> handle(const std::string& frame);
  void onStatus(const MiddlewareStatus& s);
  void onDevices(const DevicesStatus& d);
  void onTracking(const Tracking& t);
  void onCalibrationResult(const CalibrationResult& r);
  void becomeRunning();
  void enterRunning(std::string message);
  void scheduleStart();
  void timers();
  void sync();
  void enqueueReleaseAll();
};

bool Client::Impl::waitOrStop(Clock::duration d) {
  const Clock::time_point until = Clock::now() + d;
  while (!stopRequested.load()) {
    const Clock::time_point now = Clock::now();
    if (now >= until) return false;
    pollfd p{wake.fd(), POLLIN, 0};
    ::poll(&p, 1, pollMs(until - now));
    wake.drain();
  }
  return true;
}

Fd Client::Impl::connect(std::string& why) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_protocol = IPPROTO_TCP;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(settings.port);
  if (const int rc = ::getaddrinfo(settings.host.c_str(), service.c_str(), &hints, &found); rc != 0) {
    why = std::string("cannot resolve ") + settings.host + ": " + ::gai_strerror(rc);
    return {};
  }
  std::unique_ptr<addrinfo, decltype(&::freeaddrinfo)> list(found, &::freeaddrinfo);
  const Clock::time_point deadline = Clock::now() + settings.connectTimeout;
  why = "no address";
  for (const addrinfo* a = list.get(); a && !stopRequested.load(); a = a->ai_next) {
    Fd fd(::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol));
    if (!fd) {
      why = "socket: " + errnoText(errno);
      continue;
    }
    int err = 0;
    if (::connect(fd.get(), a->ai_addr, a->ai_addrlen) != 0) {
      if (errno != EINPROGRESS) {
        why = errnoText(errno);
        continue;
      }
      bool done = false;
      while (!done && !stopRequested.load()) {
        const Clock::time_point now = Clock::now();
        if (now >= deadline) break;
        pollfd p[2] = {{fd.get(), POLLOUT, 0}, {wake.fd(), POLLIN, 0}};
        if (::poll(p, 2, pollMs(deadline - now)) < 0 && errno != EINTR) break;
        if (p[1].revents) wake.drain();
        done = p[0].revents != 0;
      }
      if (!done) {
        why = stopRequested.load() ? "stopped"
                                   : "timed out after " + std::to_string(settings.connectTimeout.count()) + " ms";
        continue;
      }
      socklen_t len = sizeof err;
      if (::getsockopt(fd.get(), SOL_SOCKET, SO_ERROR, &err, &len) != 0) err = errno;
      if (err != 0) {
        why = errnoText(err);
        continue;
      }
    }
    const int one = 1;
    ::setsockopt(fd.get(), IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    return fd;
  }
  return {};
}

bool Client::Impl::flush(std::string& why) {
  std::size_t done = 0;
  while (done < outbox.size()) {
    const ssize_t n = ::send(socket.get(), outbox.data() + done, outbox.size() - done, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      done += std::size_t(n);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      break;
    } else {
      why = "send: " + errnoText(n < 0 ? errno : EPIPE);
      outbox.erase(0, done);
      return false;
    }
  }
  outbox.erase(0, done);
  if (outbox.size() > kMaxPending) {
    why = "the middleware stopped reading";
    return false;
  }
  return true;
}

bool Client::Impl::receive(std::vector<std::string>& frames, bool& closed, std::string& why) {
  char buffer[kReadChunk];
  for (int reads = 0; reads < 16; ++reads) {
    const ssize_t n = ::recv(socket.get(), buffer, sizeof buffer, MSG_DONTWAIT);
    if (n > 0) {
      splitter.feed(std::string_view(buffer, std::size_t(n)), frames);
      continue;
    }
    if (n == 0) {
      closed = true;
      return true;
    }
    if (errno == EINTR) continue;
    if (errno == EAGAIN || errno == EWOULDBLOCK) return true;
    why = "recv: " + errnoText(errno);
    return false;
  }
  return true;
}

void Client::Impl::run() noexcept {
  retry = settings.retryMin;
  while (!stopRequested.load()) {
    try {
      setState(State::Connecting);
      std::string why;
      socket = connect(why);
      if (stopRequested.load()) break;
      if (!socket) {
        setState(State::Disconnected);
        problem("connect", "cannot connect to the WEART middleware at " + endpoint() + ": " + why + " (retrying)");
        waitOrStop(retry);
        retry = std::min<Clock::duration>(retry * 2, settings.retryMax);
        continue;
      }
      if (everConnected) reconnects.fetch_add(1, std::memory_order_relaxed);
      everConnected = true;
      resolve("connect");
      event("connected to the WEART middleware at " + endpoint(), false);

      const Ending ending = session();
      switch (ending) {
        case Ending::Stopping:
          closeGracefully(true);
          break;
        case Ending::Exit:
          closeGracefully(true);
          event("the middleware closed the session; reconnecting", false);
          break;
        case Ending::PeerClosed:
        case Ending::Failed:
          socket.reset();
          break;
      }
      if (stopRequested.load()) break;
      setState(State::Disconnected);
      waitOrStop(retry);
      retry = std::min<Clock::duration>(retry * 2, settings.retryMax);
    } catch (const std::exception& e) {
      socket.reset();
      setState(State::Disconnected);
      problem(std::string("internal:") + e.what(), std::string("WEART client error: ") + e.what());
      waitOrStop(settings.retryMax);
    }
  }
  // Stopped while not connected (or the session already closed): nothing is pressing.
  socket.reset();
  setState(State::Disconnected);
}

Ending Client::Impl::session() {
  splitter.reset();
  splitterDropped = 0;
  outbox.clear();
  const HandSide hand = settings.hand;
  sentForce.fill(std::nullopt);  // unknown: the first sync sends stopForce to every idle thimble
  for (std::size_t p = 0; p < std::size_t(kPointCount); ++p) {
    sentTemperature[p] = stopTemperatureFrame(hand, Point(p));  // assumed off: only active ones are sent
    sentTexture[p] = stopTextureFrame(hand, Point(p));
  }
  sentRawData = false;
  calibrationDeadline.reset();
  startRetry = settings.retryMin;
  setState(State::Idle);

  // §4 rules 1-2: ask for the status, then start.
  const std::uint64_t ts = unixMs();
  enqueue(requestFrame("MW_GET_STATUS", ts));
  enqueue(requestFrame("DEVICES_GET_STATUS", ts));
  startAt = Clock::now();
  timers();

  std::vector<std::string> frames;
  for (;;) {
    std::string why;
    if (!flush(why)) {
      problem("lost", "lost the connection to the WEART middleware: " + why);
      return Ending::Failed;
    }
    pollfd p[2] = {{socket.get(), short(POLLIN | (outbox.empty() ? 0 : POLLOUT)), 0}, {wake.fd(), POLLIN, 0}};
    if (::poll(p, 2, int(kPollInterval.count())) < 0 && errno != EINTR) {
      problem("lost", "lost the connection to the WEART middleware: poll: " + errnoText(errno));
      return Ending::Failed;
    }
    if (p[1].revents) wake.drain();
    if (stopRequested.load()) return Ending::Stopping;
    if (p[0].revents & (POLLIN | POLLHUP | POLLERR)) {
      bool closed = false;
      frames.clear();
      const bool ok = receive(frames, closed, why);
      if (splitter.dropped() != splitterDropped) {
        malformedFrames.fetch_add(splitter.dropped() - splitterDropped, std::memory_order_relaxed);
        splitterDropped = splitter.dropped();
      }
      for (const std::string& frame : frames)
        if (const std::optional<Ending> end = handle(frame)) return *end;
      if (!ok) {
        problem("lost", "lost the connection to the WEART middleware: " + why);
        return Ending::Failed;
      }
      if (closed) {
        problem("lost", "the WEART middleware closed the connection");
        return Ending::PeerClosed;
      }
    }
    timers();
    sync();
  }
}

std::optional<Ending> Client::Impl::handle(const std::string& frame) {
  const ParsedMiddleware parsed = parseMiddlewareFrame(frame);
  if (!parsed.message) {
    malformedFrames.fetch_add(1, std::memory_order_relaxed);
    return std::nullopt;
  }
  framesReceived.fetch_add(1, std::memory_order_relaxed);
  const MiddlewareMessage& m = *parsed.message;
  if (const auto* s = std::get_if<MiddlewareStatus>(&m)) {
    onStatus(*s);
  } else if (const auto* d = std::get_if<DevicesStatus>(&m)) {
    onDevices(*d);
  } else if (const auto* t = std::get_if<Tracking>(&m)) {
    onTracking(*t);
  } else if (const auto* r = std::get_if<CalibrationResult>(&m)) {
    onCalibrationResult(*r);
  } else if (std::holds_alternative<Exit>(m) || std::holds_alternative<Disconnect>(m)) {
    return Ending::Exit;  // §4 rule 7
  }
  // CalibrationStatus, RawData, Unknown: nothing to do.
  return std::nullopt;
}

void Client::Impl::onStatus(const MiddlewareStatus& s) {
  {
    std::lock_guard lock(infoMutex);
    status = s;
  }
  if (s.statusCode != 0) {
    problem("status:" + std::to_string(s.statusCode),
            "WEART middleware error " + std::to_string(s.statusCode) + ": " +
                (s.errorDesc.empty() ? std::string("(no description)") : s.errorDesc));
  } else if (!s.errorDesc.empty()) {
    problem("statusdesc:" + s.errorDesc, "WEART middleware error: " + s.errorDesc);
  }
  if (s.statusCode == 0) resolve("status:");
  if (s.errorDesc.empty()) resolve("statusdesc:");
  if (s.warningCode != 0) {
    problem("warning:" + std::to_string(s.warningCode),
            "WEART middleware warning " + std::to_string(s.warningCode) + ": " + s.warningDesc, false);
  } else {
    resolve("warning:");
  }
  if (!s.actuationsEnabled)
    problem("actuations", "the WEART middleware has actuations disabled: the glove will not press", false);
  else
    resolve("actuations");
  if (s.status == "DISCONNECTED")
    problem("nodevice", "the WEART middleware has no glove connected", false);
  else
    resolve("nodevice");

  const State st = state.load();
  if (s.status == "RUNNING") {
    if (st == State::Starting || st == State::Idle) becomeRunning();
  } else if (s.status == "IDLE" || s.status == "DISCONNECTED" || s.status == "STOPPING") {
    if (st == State::Running || st == State::Calibrating) {
      // The middleware ended the session itself (codes 200-202, a glove lost): start it again.
      problem("stopped", "the WEART middleware stopped the session (status " + s.status + "); restarting it");
      calibrationDeadline.reset();
      setState(State::Idle);
      scheduleStart();
    } else if (st == State::Starting && (s.statusCode != 0 || s.status == "DISCONNECTED")) {
      setState(State::Idle);  // start refused (e.g. 101): retry with back-off, reported once above
      scheduleStart();
    }
  }
}

void Client::Impl::onDevices(const DevicesStatus& d) {
  {
    std::lock_guard lock(infoMutex);
    devices = d;
  }
  bool ok = true;
  for (const DevicesStatus::Device& device : d.devices) {
    if (device.hand != settings.hand) continue;
    for (const DevicesStatus::Node& node : device.nodes) {
      if (node.statusCode == 0) continue;
      ok = false;
      problem("thimble:" + std::string(wireName(node.point)) + ":" + std::to_string(node.statusCode),
              "WEART thimble " + std::string(wireName(node.point)) + " error " + std::to_string(node.statusCode) +
                  ": " + node.errorDesc);
    }
  }
  if (ok) resolve("thimble:");
}

void Client::Impl::onTracking(const Tracking& t) {
  for (const HandTracking& h : t.hands) {
    if (h.hand != settings.hand) continue;
    std::array<float, kFingerCount> c{};
    for (int f = 0; f < kFingerCount; ++f) {
      const float v = h.closure[std::size_t(pointOf(Finger(f)))];
      c[std::size_t(f)] = std::isnan(v) ? 0.0f : std::clamp(v, 0.0f, 1.0f);
    }
    std::lock_guard lock(infoMutex);
    closures = c;
  }
}

void Client::Impl::onCalibrationResult(const CalibrationResult& r) {
  if (r.hand != settings.hand || state.load() != State::Calibrating) return;
  calibrated = true;
  calibrationDeadline.reset();
  enqueue(stopCalibrationFrame());
  if (r.success) {
    resolve("calibration");
    enterRunning("running (tracking calibrated)");
  } else {
    problem("calibration", "tracking calibration failed for the " + std::string(wireName(settings.hand)) + " hand");
    enterRunning("running (uncalibrated)");
  }
}

void Client::Impl::becomeRunning() {
  resolve("lost");
  resolve("stopped");
  resolve("starttimeout");
  retry = settings.retryMin;
  startRetry = settings.retryMin;
  startAt.reset();
  if (settings.calibrate && !calibrated) {
    enqueue(startCalibrationFrame());  // §4 rule 4
    calibrationDeadline = Clock::now() + kCalibrationTimeout;
    setState(State::Calibrating);
    event("running; calibrating the " + std::string(wireName(settings.hand)) + " hand (hold it still)", false);
  } else {
    enterRunning("running");
  }
}

void Client::Impl::enterRunning(std::string message) {
  setState(State::Running);
  event(std::move(message), false);
}

void Client::Impl::scheduleStart() {
  startAt = Clock::now() + startRetry;
  startRetry = std::min<Clock::duration>(startRetry * 2, settings.retryMax);
}

void Client::Impl::timers() {
  const Clock::time_point now = Clock::now();
  if (startAt && now >= *startAt) {
    startAt.reset();
    enqueue(startFrame());
    startSentAt = now;
    setState(State::Starting);
  }
  constexpr std::chrono::seconds kStartTimeout{10};
  if (state.load() == State::Starting && !startAt && now - startSentAt > kStartTimeout) {
    problem("starttimeout", "the WEART middleware did not start the session within 10 s; asking again");
    setState(State::Idle);
    scheduleStart();
  }
  if (calibrationDeadline && now >= *calibrationDeadline) {
    calibrationDeadline.reset();
    calibrated = true;
    enqueue(stopCalibrationFrame());
    problem("calibration", "no calibration result within 30 s; carrying on uncalibrated");
    enterRunning("running (uncalibrated)");
  }
}

void Client::Impl::sync() {
  Desired d;
  {
    std::lock_guard lock(desiredMutex);
    d = desired;
  }
  // The watchdog runs in every state, so a stall is always counted and the next session starts released.
  const bool stalled = d.published && Clock::now() - d.lastPublish > settings.watchdog;
  if (stalled && !watchdogTripped) {
    watchdogTripped = true;
    watchdogTrips.fetch_add(1, std::memory_order_relaxed);
    sentForce.fill(std::nullopt);  // release every thimble, whatever it was sent
    event("simulation stalled: glove released", true);
  } else if (!stalled && watchdogTripped) {
    watchdogTripped = false;
    event("simulation resumed: forces restored", false);
  }

  const State st = state.load();
  if (st != State::Running && st != State::Calibrating) return;  // §4 rule 3
  if (!outbox.empty()) return;  // the socket is behind: the newest values go out once it drains

  const HandSide hand = settings.hand;
  auto send = [&](std::optional<std::string>& sent, std::string frame) {
    if (sent != frame) {
      enqueue(frame);
      sent = std::move(frame);
    }
  };
  for (Point point : settings.thimbles) {
    const std::size_t p = std::size_t(point);
    const float force = watchdogTripped ? 0.0f : d.force[p];
    send(sentForce[p], force > 0.0f ? forceFrame(hand, point, force) : stopForceFrame(hand, point));
    send(sentTemperature[p],
         d.temperature[p] ? temperatureFrame(hand, point, *d.temperature[p]) : stopTemperatureFrame(hand, point));
    const std::optional<Texture>& t = d.texture[p];
    send(sentTexture[p],
         t ? textureFrame(hand, point, t->index, t->velocity, t->volume) : stopTextureFrame(hand, point));
  }
  if (d.rawData != sentRawData) {
    enqueue(requestFrame(d.rawData ? "RAW_DATA_ON" : "RAW_DATA_OFF", unixMs()));
    sentRawData = d.rawData;
  }
}

void Client::Impl::enqueueReleaseAll() {
  const HandSide hand = settings.hand;
  for (Point point : settings.thimbles) {
    const std::size_t p = std::size_t(point);
    enqueue(stopForceFrame(hand, point));
    sentForce[p] = stopForceFrame(hand, point);
    if (sentTemperature[p] != stopTemperatureFrame(hand, point)) {
      enqueue(stopTemperatureFrame(hand, point));
      sentTemperature[p] = stopTemperatureFrame(hand, point);
    }
    if (sentTexture[p] != stopTextureFrame(hand, point)) {
      enqueue(stopTextureFrame(hand, point));
      sentTexture[p] = stopTextureFrame(hand, point);
    }
  }
  if (sentRawData) enqueue(requestFrame("RAW_DATA_OFF", unixMs()));
  sentRawData = false;
  enqueue(stopFrame());  // §4 rule 6
}

void Client::Impl::closeGracefully(bool releaseAll) {
  if (stopRequested.load()) setState(State::Stopping);
  if (releaseAll) enqueueReleaseAll();  // after any half-written frame still in the outbox
  // Write everything, within a bound.
  const Clock::time_point flushUntil = Clock::now() + kCloseFlushTime;
  std::string why;
  bool ok = true;
  while (ok && !outbox.empty()) {
    ok = flush(why);
    const Clock::time_point now = Clock::now();
    if (!ok || outbox.empty() || now >= flushUntil) break;
    pollfd p{socket.get(), POLLOUT, 0};
    ::poll(&p, 1, pollMs(flushUntil - now));
  }
  if (ok && outbox.empty()) {
    // Half-close and read until the middleware closes too: closing with unread data would reset
    // the connection, and the middleware could lose the stop frames it has not read yet.
    ::shutdown(socket.get(), SHUT_WR);
    const Clock::time_point drainUntil = Clock::now() + kCloseDrainTime;
    char buffer[kReadChunk];
    for (;;) {
      const Clock::time_point now = Clock::now();
      if (now >= drainUntil) break;
      pollfd p{socket.get(), POLLIN, 0};
      const int rc = ::poll(&p, 1, pollMs(drainUntil - now));
      if (rc < 0 && errno == EINTR) continue;
      if (rc <= 0) break;
      const ssize_t n = ::recv(socket.get(), buffer, sizeof buffer, MSG_DONTWAIT);
      if (n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) break;
    }
  }
  outbox.clear();
  socket.reset();
}

// --- Client --------------------------------------------------------------------------------------

namespace {

void validate(const ClientSettings& s) {
  if (s.host.empty()) throw Error("WEART client: empty host");
  if (s.port == 0) throw Error("WEART client: port 0");
  if (s.thimbles.empty()) throw Error("WEART client: no thimbles");
  std::array<bool, kPointCount> seen{};
  for (Point p : s.thimbles) {
    if (std::size_t(p) >= std::size_t(kPointCount)) throw Error("WEART client: unknown point");
    if (seen[std::size_t(p)]) throw Error("WEART client: thimble " + std::string(wireName(p)) + " given twice");
    seen[std::size_t(p)] = true;
  }
  if (s.hand != HandSide::Left && s.hand != HandSide::Right) throw Error("WEART client: unknown hand");
  auto positive = [](std::chrono::milliseconds v, const char* name) {
    if (v.count() <= 0) throw Error(std::string("WEART client: ") + name + " must be positive");
  };
  positive(s.watchdog, "watchdog");
  positive(s.connectTimeout, "connectTimeout");
  positive(s.retryMin, "retryMin");
  if (s.retryMax < s.retryMin) throw Error("WEART client: retryMax is below retryMin");
}

}  // namespace

Client::Client(ClientSettings settings) {
  validate(settings);
  impl_ = std::make_unique<Impl>(std::move(settings));
}

Client::~Client() { shutdown(); }

void Client::start() {
  if (impl_->shutDown.load()) throw Error("WEART client: start() after shutdown()");
  if (impl_->thread.joinable()) return;
  Impl* impl = impl_.get();
  impl_->thread = std::thread([impl] { impl->run(); });
}

void Client::shutdown() noexcept {
  if (impl_->shutDown.exchange(true)) return;
  impl_->stopRequested.store(true);
  impl_->wake.notify();
  if (impl_->thread.joinable()) impl_->thread.join();
  impl_->setState(State::Disconnected);
}

void Client::publishForces(const std::array<float, kFingerCount>& force) {
  std::array<float, kPointCount> values{};
  for (int f = 0; f < kFingerCount; ++f) {
    const std::size_t p = std::size_t(pointOf(Finger(f)));
    if (impl_->isThimble[p]) values[p] = clampUnit(force[std::size_t(f)]);
  }
  const Clock::time_point now = Clock::now();
  bool changed = false;
  {
    std::lock_guard lock(impl_->desiredMutex);
    changed = impl_->desired.force != values;
    impl_->desired.force = values;
    impl_->desired.published = true;
    impl_->desired.lastPublish = now;
  }
  if (changed) impl_->wake.notify();  // the new force leaves now, not at the I/O thread's next poll
}

std::optional<std::array<float, kFingerCount>> Client::closures() const {
  std::lock_guard lock(impl_->infoMutex);
  return impl_->closures;
}

State Client::state() const { return impl_->state.load(); }

std::optional<MiddlewareStatus> Client::lastStatus() const {
  std::lock_guard lock(impl_->infoMutex);
  return impl_->status;
}

std::optional<DevicesStatus> Client::lastDevices() const {
  std::lock_guard lock(impl_->infoMutex);
  return impl_->devices;
}

std::vector<Event> Client::takeEvents() {
  std::lock_guard lock(impl_->infoMutex);
  std::vector<Event> out(std::make_move_iterator(impl_->events.begin()), std::make_move_iterator(impl_->events.end()));
  impl_->events.clear();
  return out;
}

void Client::setTemperature(Point point, std::optional<float> value) {
  const std::size_t p = std::size_t(point);
  if (p >= std::size_t(kPointCount) || !impl_->isThimble[p]) return;
  if (value && std::isnan(*value)) value.reset();
  if (value) value = std::clamp(*value, 0.0f, 1.0f);
  std::lock_guard lock(impl_->desiredMutex);
  impl_->desired.temperature[p] = value;
}

void Client::setTexture(Point point, std::optional<Texture> texture) {
  const std::size_t p = std::size_t(point);
  if (p >= std::size_t(kPointCount) || !impl_->isThimble[p]) return;
  if (texture) {
    texture->velocity = std::isnan(texture->velocity) ? 0.0f : std::clamp(texture->velocity, 0.0f, 0.5f);
    texture->volume = std::isnan(texture->volume) ? 0.0f : std::clamp(texture->volume, 0.0f, 100.0f);
    if (texture->index < 0 || texture->index > 21) texture->index = 255;
  }
  std::lock_guard lock(impl_->desiredMutex);
  impl_->desired.texture[p] = texture;
}

void Client::setRawData(bool on) {
  std::lock_guard lock(impl_->desiredMutex);
  impl_->desired.rawData = on;
}

Stats Client::stats() const {
  Stats s;
  s.framesSent = impl_->framesSent.load();
  s.framesReceived = impl_->framesReceived.load();
  s.malformedFrames = impl_->malformedFrames.load();
  s.reconnects = impl_->reconnects.load();
  s.watchdogTrips = impl_->watchdogTrips.load();
  return s;
}

const ClientSettings& Client::settings() const { return impl_->settings; }

}  // namespace vrd::weart
