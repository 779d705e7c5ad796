// The fake middleware driven the way the vendor's example programs drive the middleware: connect,
// register a status listener only afterwards (so the push on connect is missed), never ask for the
// status, and wait for a connected device, then for raw data of every finger. The client here is
// a bare socket speaking the wire text of the vendor's Python SDK, not our WeartClient.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "vrdeform/core/posix_fd.h"
#include "vrdeform/devices/weart_protocol.h"
#include "vrdeform/testing/fake_middleware.h"

namespace vrd::weart {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

constexpr auto kExampleWait = 1s;  // what an example may wait for what it waits for
constexpr auto kSetupWait = 5s;    // bound of the set-up steps

// One middleware frame as received: its text and what it parses to.
struct Received {
  std::string text;
  ParsedMiddleware parsed;
  template <typename T>
  const T* as() const {
    return parsed.message ? std::get_if<T>(&*parsed.message) : nullptr;
  }
};

class ExampleClient {
 public:
  /// `receiveBuffer`: SO_RCVBUF in bytes (0: the system's).
  explicit ExampleClient(std::uint16_t port, int receiveBuffer = 0)
      : socket_(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0)) {
    if (receiveBuffer > 0) ::setsockopt(socket_.get(), SOL_SOCKET, SO_RCVBUF, &receiveBuffer, sizeof receiveBuffer);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(port);
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = socket_ && ::connect(socket_.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0;
  }
  bool connected() const { return connected_; }

  void send(const std::string& frame) {
    ASSERT_EQ(::send(socket_.get(), frame.data(), frame.size(), MSG_NOSIGNAL), ssize_t(frame.size()));
  }

  /// Reads until `done` accepts a frame or `timeout` passes; frames are consumed as they come.
  bool waitFor(const std::function<bool(const Received&)>& done, Clock::duration timeout) {
    const Clock::time_point until = Clock::now() + timeout;
    while (true) {
      while (!pending_.empty()) {
        Received r{pending_.front(), parseMiddlewareFrame(pending_.front())};
        pending_.erase(pending_.begin());
        if (!r.parsed.message) ++malformed_;
        if (done(r)) return true;
      }
      const Clock::time_point now = Clock::now();
      if (now >= until || !read(until - now)) return false;
    }
  }

  /// What a listener registered after Run() never sees: the frames up to the first one and those
  /// arriving within 50 ms of it.
  bool missTheFirstPush() {
    if (!waitFor([](const Received&) { return true; }, kSetupWait)) return false;
    const Clock::time_point until = Clock::now() + 50ms;
    while (Clock::now() < until) read(until - Clock::now());
    pending_.clear();
    return true;
  }

  int malformed() const { return malformed_; }

 private:
  bool read(Clock::duration timeout) {
    pollfd p{socket_.get(), POLLIN, 0};
    if (::poll(&p, 1, pollMs(timeout)) <= 0) return true;
    char buffer[65536];
    const ssize_t n = ::recv(socket_.get(), buffer, sizeof buffer, 0);
    if (n <= 0) return false;
    splitter_.feed(std::string_view(buffer, std::size_t(n)), pending_);
    return true;
  }

  Fd socket_;
  bool connected_ = false;
  FrameSplitter splitter_;
  std::vector<std::string> pending_;
  int malformed_ = 0;
};

// The Python SDK's frames (protocol notes §2.1, §6.1, §6.7).
std::string pythonRequest(std::string_view type) {
  return "{\"type\": \"" + std::string(type) + "\", \"ts\": 1717600000000}~";
}
const std::string kPythonStart = "StartFromClient:SdkLLPY:2.0.3:TrackType1~";

bool hasDevice(const MiddlewareStatus& s, HandSide hand) {
  return std::any_of(s.connectedDevices.begin(), s.connectedDevices.end(),
                     [hand](const MiddlewareStatus::Device& d) { return d.hand == hand; });
}

struct Flavour {
  bool pro;
  HandSide hand;
  std::vector<Point> rawPoints;  // every node and, on a G1, the control unit
};
const Flavour kFlavours[] = {
    {false, HandSide::Right, {Point::Thumb, Point::Index, Point::Middle, Point::Palm}},
    {true, HandSide::Left, {Point::Thumb, Point::Index, Point::Middle, Point::Annular, Point::Pinky, Point::Palm}},
};

FakeMiddlewareSettings settingsOf(const Flavour& f) {
  FakeMiddlewareSettings s;
  s.pro = f.pro;
  s.hands = {f.hand};
  return s;
}

// Connects, misses the first push, then waits passively for a connected device and its status.
void waitForADevicePassively(ExampleClient& client, const Flavour& f) {
  ASSERT_TRUE(client.connected());
  ASSERT_TRUE(client.missTheFirstPush());
  bool status = false, devices = false;
  EXPECT_TRUE(client.waitFor(
      [&](const Received& r) {
        if (const auto* s = r.as<MiddlewareStatus>()) status |= s->pro == f.pro && hasDevice(*s, f.hand);
        if (const auto* d = r.as<DevicesStatus>())
          devices |= d->pro == f.pro && d->devices.size() == 1 && d->devices[0].hand == f.hand;
        return status && devices;
      },
      kExampleWait))
      << (f.pro ? "Pro" : "G1") << ": status " << status << ", device status " << devices;
}

TEST(WeartVendorStyle, ALateListenerSeesAConnectedDeviceWithinASecond) {
  for (const Flavour& f : kFlavours) {
    FakeMiddleware fake(settingsOf(f));
    fake.start();
    ExampleClient client(fake.port());
    waitForADevicePassively(client, f);
    EXPECT_TRUE(fake.commands().empty()) << "the example never asks";
    EXPECT_EQ(client.malformed(), 0);
  }
}

TEST(WeartVendorStyle, RawDataOfEveryNodeWithinASecond) {
  for (const Flavour& f : kFlavours) {
    FakeMiddleware fake(settingsOf(f));
    fake.start();
    ExampleClient client(fake.port());
    waitForADevicePassively(client, f);
    client.send(kPythonStart);
    ASSERT_TRUE(client.waitFor(
        [](const Received& r) {
          const auto* s = r.as<MiddlewareStatus>();
          return s && s->status == "RUNNING";
        },
        kSetupWait));
    client.send(pythonRequest("RAW_DATA_ON"));
    std::set<Point> seen;
    const std::string type = f.pro ? "RAW_DATA_TD_PRO" : "RAW_DATA";
    EXPECT_TRUE(client.waitFor(
        [&](const Received& r) {
          if (const auto* raw = r.as<RawData>(); raw && raw->type == type && raw->hand == f.hand)
            seen.insert(raw->points.begin(), raw->points.end());
          return seen.size() == f.rawPoints.size();
        },
        kExampleWait))
        << type << ": " << seen.size() << " of " << f.rawPoints.size() << " points";
    EXPECT_EQ(seen, std::set<Point>(f.rawPoints.begin(), f.rawPoints.end()));
    EXPECT_EQ(client.malformed(), 0);
  }
}

TEST(WeartVendorStyle, ProStatusIsCompleteAndAgreesWithItsDevices) {
  FakeMiddleware fake(settingsOf(kFlavours[1]));
  fake.start();
  ExampleClient client(fake.port());
  ASSERT_TRUE(client.connected());
  std::optional<Received> status, devices;
  ASSERT_TRUE(client.waitFor(
      [&](const Received& r) {
        if (r.as<MiddlewareStatus>()) status = r;
        if (r.as<DevicesStatus>()) devices = r;
        return status && devices;
      },
      kSetupWait));
  // §7.8's keys, every one of them (the Python SDK reads a missing one as None).
  for (const char* key : {"\"signalStrength\":", "\"sensorsCalibDate\":\"", "\"chargeCompleted\":", "\"bluetoothOn\":",
                          "\"bluetoothConnected\":", "\"wifiOn\":", "\"wifiConnected\":", "\"usbConnected\":",
                          "\"buttonPushed\":", "\"imuFault\":", "\"adcFault\":", "\"tofFault\":"})
    EXPECT_NE(devices->text.find(key), std::string::npos) << key << " in " << devices->text;
  const MiddlewareStatus& wa = *status->as<MiddlewareStatus>();
  const DevicesStatus& pro = *devices->as<DevicesStatus>();
  ASSERT_TRUE(wa.pro && pro.pro);
  ASSERT_EQ(pro.devices.size(), wa.connectedDevices.size());
  for (std::size_t i = 0; i < pro.devices.size(); ++i) {
    const DevicesStatus::Device& d = pro.devices[i];
    EXPECT_EQ(d.macAddress, wa.connectedDevices[i].macAddress);
    EXPECT_EQ(d.hand, wa.connectedDevices[i].hand);
    EXPECT_LT(d.signalStrength, 0.0) << "an RSSI in dBm";
    EXPECT_FALSE(d.sensorsCalibDate.empty());
    // WA_STATUS names the link the master reports connected.
    const DevicesStatus::Connection& c = d.connection;
    const std::string link = c.usbConnected ? "USB" : c.wifiConnected ? "WIFI" : c.bluetoothConnected ? "BLE" : "NONE";
    EXPECT_EQ(wa.connectionType, link);
    EXPECT_NE(link, "NONE") << "a connected glove has a link";
  }
}

TEST(WeartVendorStyle, BareStartStreamsDefaultTrackingOnAG1) {
  FakeMiddlewareSettings fs;
  fs.tracking = [](double) { return std::array<float, kFingerCount>{0.2f, 0.8f, 0.5f, 0.5f, 0.5f}; };
  FakeMiddleware fake(fs);
  fake.start();
  for (const bool bare : {true, false}) {
    ExampleClient client(fake.port());
    ASSERT_TRUE(client.connected());
    client.send(bare ? "StartFromClient~" : kPythonStart);
    int frames = 0;
    ASSERT_TRUE(client.waitFor(
        [&](const Received& r) {
          if (r.text.rfind("Tracking", 0) != 0) return false;
          EXPECT_EQ(r.text.rfind("Tracking:TrackType1:", 0) == 0, !bare) << r.text;
          const Tracking* t = r.as<Tracking>();
          EXPECT_TRUE(t) << r.text;
          if (t && bare) {  // §7.3.1: thumb, index, middle, palm; no abduction
            const HandTracking& right = t->hands.at(0);
            EXPECT_NEAR(right.closure[std::size_t(Point::Thumb)], 0.2f, 0.01f);
            EXPECT_NEAR(right.closure[std::size_t(Point::Index)], 0.8f, 0.01f);
            EXPECT_NEAR(right.closure[std::size_t(Point::Middle)], 0.5f, 0.01f);
            EXPECT_TRUE(std::isnan(right.thumbAbduction));
          }
          return ++frames == 10;
        },
        kSetupWait));
    client.send("StopFromClient~");
  }
}

TEST(WeartVendorStyle, BareStartOnAProStreamsItsOwnTracking) {
  FakeMiddleware fake(settingsOf(kFlavours[1]));
  fake.start();
  ExampleClient client(fake.port());
  ASSERT_TRUE(client.connected());
  client.send("StartFromClient~");
  int frames = 0;
  ASSERT_TRUE(client.waitFor(
      [&](const Received& r) {
        EXPECT_NE(r.text.rfind("Tracking", 0), 0u) << "no CSV tracking from a Pro: " << r.text;
        if (const Tracking* t = r.as<Tracking>(); t && t->hands.size() == 1) ++frames;
        return frames == 10;
      },
      kSetupWait));
}

TEST(WeartVendorStyle, StatusIsRepeatedAtTheSetPeriodAndOnChanges) {
  FakeMiddlewareSettings fs;
  fs.statusPeriod = 20ms;
  FakeMiddleware fast(fs);
  fast.start();
  ExampleClient client(fast.port());
  ASSERT_TRUE(client.connected());
  int statuses = 0, devices = 0;
  ASSERT_TRUE(client.waitFor(
      [&](const Received& r) {
        statuses += r.as<MiddlewareStatus>() != nullptr;
        devices += r.as<DevicesStatus>() != nullptr;
        return statuses >= 10 && devices >= 10;
      },
      kSetupWait));
  EXPECT_TRUE(fast.commands().empty());

  fs.statusPeriod = 0ms;  // on connect and on change only
  FakeMiddleware quiet(fs);
  quiet.start();
  ExampleClient other(quiet.port());
  ASSERT_TRUE(other.connected());
  statuses = 0;
  auto countStatus = [&](const Received& r) {
    statuses += r.as<MiddlewareStatus>() != nullptr;
    return false;
  };
  other.waitFor(countStatus, 300ms);
  EXPECT_EQ(statuses, 1);
  other.send(kPythonStart);
  std::vector<std::string> changes;
  ASSERT_TRUE(other.waitFor(
      [&](const Received& r) {
        if (const auto* s = r.as<MiddlewareStatus>()) changes.push_back(s->status);
        return !changes.empty() && changes.back() == "RUNNING";
      },
      kSetupWait));
  EXPECT_EQ(changes, (std::vector<std::string>{"STARTING", "RUNNING"}));
}

TEST(WeartVendorStyle, AStartErrorIsRepeatedUntilTheNextStart) {
  FakeMiddlewareSettings fs;
  fs.statusPeriod = 20ms;
  FakeMiddleware fake(fs);
  fake.setStartError(101);
  fake.start();
  ExampleClient client(fake.port());
  ASSERT_TRUE(client.connected());
  client.send(kPythonStart);
  int refused = 0;
  ASSERT_TRUE(client.waitFor(
      [&](const Received& r) {
        const auto* s = r.as<MiddlewareStatus>();
        refused += s && s->statusCode == 101;
        return refused == 3;  // the reply and two periodic pushes
      },
      kSetupWait));
  fake.setStartError(0);
  client.send(kPythonStart);
  ASSERT_TRUE(client.waitFor(
      [](const Received& r) {
        const auto* s = r.as<MiddlewareStatus>();
        return s && s->status == "RUNNING" && s->statusCode == 0;
      },
      kSetupWait));
}

// A client that stops reading blocks the fake's writes (for up to a second each); stop() must not
// wait for them.
TEST(WeartVendorStyle, StopIsPromptWhileWritingToAClientThatDoesNotRead) {
  FakeMiddlewareSettings fs = settingsOf(kFlavours[1]);
  fs.hands = {HandSide::Left, HandSide::Right};
  fs.trackingHz = 1000.0;
  FakeMiddleware fake(fs);
  fake.start();
  ExampleClient client(fake.port(), 4096);
  ASSERT_TRUE(client.connected());
  client.send(kPythonStart);
  client.send(pythonRequest("RAW_DATA_ON"));
  // Blocked: no tracking frame has gone out for 200 ms.
  std::uint64_t sent = fake.trackingFramesSent();
  Clock::time_point changed = Clock::now();
  const Clock::time_point until = Clock::now() + 30s;
  while (Clock::now() - changed < 200ms) {
    ASSERT_LT(Clock::now(), until) << "the fake never blocked";
    std::this_thread::sleep_for(10ms);
    if (const std::uint64_t now = fake.trackingFramesSent(); now != sent) {
      sent = now;
      changed = Clock::now();
    }
  }
  ASSERT_TRUE(fake.clientConnected());
  const Clock::time_point before = Clock::now();
  fake.stop();
  EXPECT_LT(Clock::now() - before, 500ms) << "stop() waited for the blocked write";
}

}  // namespace
}  // namespace vrd::weart
