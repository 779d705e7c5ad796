// The WEART client against the fake middleware over loopback: session flow, latched haptics,
// reconnects, the watchdog, shutdown (also by exception and by signal), garbage and slow peers.
// Every wait polls a condition with a generous bound; nothing depends on tight timing.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <limits>
#include <mutex>
#include <ostream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "test_support.h"
#include "vrdeform/devices/stop_signals.h"
#include "vrdeform/devices/weart_client.h"
#include "vrdeform/haptics/haptic_session.h"
#include "vrdeform/testing/fake_middleware.h"

namespace vrd::weart {

// For gtest's failure messages.
inline void PrintTo(State state, std::ostream* os) { *os << toString(state); }

namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using Kind = ClientCommand::Kind;
using Forces = std::array<float, kFingerCount>;

constexpr auto kWait = 5s;  // bound of every wait for something the other side does
constexpr std::array<Point, 3> kG1{Point::Thumb, Point::Index, Point::Middle};

// Polls `done` every millisecond up to `timeout`, running `each` (e.g. a publish) in between.
template <typename Done, typename Each>
bool waitFor(Done&& done, Each&& each, Clock::duration timeout = kWait) {
  const Clock::time_point until = Clock::now() + timeout;
  while (!done()) {
    if (Clock::now() >= until) return false;
    each();
    std::this_thread::sleep_for(1ms);
  }
  return true;
}
template <typename Done>
bool waitFor(Done&& done, Clock::duration timeout = kWait) {
  return waitFor(
      std::forward<Done>(done), [] {}, timeout);
}

// A simulation loop: publishes its forces every millisecond from its own thread.
class Publisher {
 public:
  explicit Publisher(Client& client, Forces forces = {}) : forces_(forces) {
    thread_ = std::thread([this, &client] {
      while (!stop_.load()) {
        Forces f;
        {
          std::lock_guard lock(mutex_);
          f = forces_;
        }
        client.publishForces(f);
        std::this_thread::sleep_for(1ms);
      }
    });
  }
  ~Publisher() { stop(); }
  void set(const Forces& f) {
    std::lock_guard lock(mutex_);
    forces_ = f;
  }
  void stop() {
    stop_.store(true);
    if (thread_.joinable()) thread_.join();
  }

 private:
  std::mutex mutex_;
  Forces forces_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

ClientSettings settingsFor(const FakeMiddleware& fake) {
  ClientSettings s;
  s.port = fake.port();
  s.retryMin = 20ms;
  s.retryMax = 200ms;
  // A test thread held up for 50 ms on a loaded machine must not trip the watchdog: only the
  // watchdog test uses the real 50 ms.
  s.watchdog = 2s;
  return s;
}

std::vector<ReceivedCommand> commandsOf(const FakeMiddleware& fake, Kind kind, std::optional<Point> point = {},
                                        Clock::time_point after = {}) {
  std::vector<ReceivedCommand> out;
  for (const ReceivedCommand& c : fake.commands())
    if (c.command.kind == kind && (!point || c.command.point == *point) && c.time > after) out.push_back(c);
  return out;
}

std::size_t countEvents(const std::vector<Event>& events, std::string_view text, bool error) {
  return std::size_t(std::count_if(events.begin(), events.end(), [&](const Event& e) {
    return e.error == error && e.message.find(text) != std::string::npos;
  }));
}

std::string listed(const std::vector<Event>& events) {
  std::string s;
  for (const Event& e : events) s += (e.error ? "  [error] " : "  ") + e.message + "\n";
  return s;
}

bool latchedAll(const FakeMiddleware& fake, float value, HandSide hand = HandSide::Right) {
  return std::all_of(kG1.begin(), kG1.end(), [&](Point p) { return fake.latchedForce(hand, p) == value; });
}

bool near(float a, float b, float tolerance) { return std::abs(a - b) <= tolerance; }

// G1 tracking travels as 0-255.
constexpr float kByte = 1.0f / 255.0f + 1e-4f;

// --- parseEndpoint, pointOf, settings --------------------------------------------------------------

TEST(WeartEndpoint, ParsesHostPortForms) {
  ClientSettings base;
  base.hand = HandSide::Left;
  ClientSettings s = parseEndpoint("example.org:1234", base);
  EXPECT_EQ(s.host, "example.org");
  EXPECT_EQ(s.port, 1234);
  EXPECT_EQ(s.hand, HandSide::Left);  // the rest comes from base
  s = parseEndpoint("10.0.0.2");
  EXPECT_EQ(s.host, "10.0.0.2");
  EXPECT_EQ(s.port, 13031);
  s = parseEndpoint(":9000");
  EXPECT_EQ(s.host, "127.0.0.1");
  EXPECT_EQ(s.port, 9000);
  s = parseEndpoint("[::1]:13032");
  EXPECT_EQ(s.host, "::1");
  EXPECT_EQ(s.port, 13032);
  s = parseEndpoint("[fe80::1%eth0]:5");
  EXPECT_EQ(s.host, "fe80::1%eth0");
  EXPECT_EQ(s.port, 5);
  s = parseEndpoint("::1");
  EXPECT_EQ(s.host, "::1");
  EXPECT_EQ(s.port, 13031);
  s = parseEndpoint("[::ffff:10.1.2.3]");
  EXPECT_EQ(s.host, "::ffff:10.1.2.3");
  s = parseEndpoint("glove-pc_2:65535");
  EXPECT_EQ(s.host, "glove-pc_2");
  EXPECT_EQ(s.port, 65535);
}

TEST(WeartEndpoint, RejectsGarbage) {
  for (const char* bad :
       {"",          ":",        "host:",    "host:0",      "host:65536",  "host:12a",
        "host:-1",   "host: 1",  "[::1",     "[::1]x",      "[::1]:",      "[]:5",
        "[zz::1]:5", "a b:1",    "host:1:2", "~:1",         "h\xc3\xa9:1", "host:99999999999999999999",
        "::::",      "[::::]:5", "1::2::3",  "[fe80::1%]:5"}) {
    const std::string message = vrd::testing::errorOf([&] { parseEndpoint(bad); });
    EXPECT_NE(message.find("WEART endpoint"), std::string::npos) << "'" << bad << "': " << message;
  }
}

TEST(WeartClientSettings, PointOfEachFinger) {
  EXPECT_EQ(pointOf(Finger::Thumb), Point::Thumb);
  EXPECT_EQ(pointOf(Finger::Index), Point::Index);
  EXPECT_EQ(pointOf(Finger::Middle), Point::Middle);
  EXPECT_EQ(pointOf(Finger::Ring), Point::Annular);
  EXPECT_EQ(pointOf(Finger::Little), Point::Pinky);
}

TEST(WeartClientSettings, RejectsBadSettings) {
  auto with = [](auto edit) {
    ClientSettings s;
    edit(s);
    return vrd::testing::errorOf([&] { Client c(s); });
  };
  EXPECT_NE(with([](ClientSettings& s) { s.port = 0; }).find("port"), std::string::npos);
  EXPECT_NE(with([](ClientSettings& s) { s.host.clear(); }).find("host"), std::string::npos);
  EXPECT_NE(with([](ClientSettings& s) { s.thimbles.clear(); }).find("thimbles"), std::string::npos);
  EXPECT_NE(with([](ClientSettings& s) {
              s.thimbles = {Point::Index, Point::Index};
            }).find("INDEX"),
            std::string::npos);
  EXPECT_NE(with([](ClientSettings& s) { s.watchdog = 0ms; }).find("watchdog"), std::string::npos);
  EXPECT_NE(with([](ClientSettings& s) { s.retryMax = 1ms; }).find("retryMax"), std::string::npos);
  Client fine{ClientSettings{}};  // no I/O until start()
  EXPECT_EQ(fine.state(), State::Disconnected);
  fine.shutdown();
  EXPECT_NE(vrd::testing::errorOf([&] { fine.start(); }).find("after shutdown"), std::string::npos);
}

// --- the fake's tracking script ----------------------------------------------------------------------

TEST(WeartFakeMiddleware, TrackingScriptInterpolates) {
  const TrackingScript script = TrackingScript::parse(
      "# t thumb index middle [ring little]\n"
      "0   0 0 0\n"
      "1.0 0.2 0.8 0.4   # ring, little follow middle\n"
      "2.0 0 1 0 0.5 0.25\n");
  ASSERT_EQ(script.keys().size(), 3u);
  EXPECT_EQ(script.at(-1)[1], 0.0f);
  EXPECT_NEAR(script.at(0.5)[1], 0.4f, 1e-6f);
  EXPECT_NEAR(script.at(1.0)[3], 0.4f, 1e-6f);
  EXPECT_NEAR(script.at(1.5)[4], 0.325f, 1e-6f);
  EXPECT_EQ(script.at(99)[4], 0.25f);
  EXPECT_NEAR(script.source()(0.25)[0], 0.05f, 1e-6f);
  for (const char* bad : {"", "# nothing\n", "0 0 0\n", "0 0 0 0 0\n", "0 0 0 x\n", "0 0 0 1.5\n",
                          "1 0 0 0\n0.5 0 0 0\n", "-1 0 0 0\n", "0 nan 0 0\n"}) {
    const std::string message = vrd::testing::errorOf([&] { TrackingScript::parse(bad, "t.script"); });
    EXPECT_NE(message.find("t.script"), std::string::npos) << message;
  }
  EXPECT_NE(vrd::testing::errorOf([] { TrackingScript::parse("0 0 0 0\n0.5 0 0 0\n0.5 1 1 1\n", "s"); }).find("s:3:"),
            std::string::npos);
}

// --- sessions ------------------------------------------------------------------------------------

TEST(WeartClient, FullSession) {
  std::atomic<float> indexClosure{0.1f};
  FakeMiddlewareSettings fs;
  fs.tracking = [&](double) { return Forces{0.2f, indexClosure.load(), 0.3f, 0.9f, 0.9f}; };
  FakeMiddleware fake(fs);
  fake.start();
  Client client(settingsFor(fake));
  EXPECT_FALSE(client.closures());
  client.start();
  Publisher sim(client);
  std::vector<Event> events;
  auto collect = [&] {
    for (Event& e : client.takeEvents()) events.push_back(std::move(e));
  };

  ASSERT_TRUE(waitFor([&] { return client.state() == State::Running; })) << toString(client.state());
  ASSERT_TRUE(waitFor([&] {
    return client.lastStatus() && client.lastStatus()->status == "RUNNING" &&
           !commandsOf(fake, Kind::StopCalibration).empty();
  }));
  EXPECT_EQ(fake.status(), "RUNNING");

  // §4: status requests, start with TrackType1, then calibration start and stop, in that order.
  const std::vector<ReceivedCommand> all = fake.commands();
  auto firstOf = [&](Kind kind, std::string_view text = {}) {
    for (std::size_t i = 0; i < all.size(); ++i)
      if (all[i].command.kind == kind && (text.empty() || all[i].command.text == text)) return i;
    return std::numeric_limits<std::size_t>::max();
  };
  const std::size_t mw = firstOf(Kind::Request, "MW_GET_STATUS"), dev = firstOf(Kind::Request, "DEVICES_GET_STATUS");
  const std::size_t start = firstOf(Kind::Start), calStart = firstOf(Kind::StartCalibration);
  ASSERT_LT(start, all.size());
  EXPECT_LT(mw, start);
  EXPECT_LT(dev, start);
  EXPECT_EQ(all[start].command.text, "TrackType1");
  ASSERT_LT(calStart, all.size());
  EXPECT_LT(start, calStart);
  EXPECT_LT(calStart, firstOf(Kind::StopCalibration));
  ASSERT_TRUE(client.lastDevices());
  ASSERT_EQ(client.lastDevices()->devices.size(), 1u);
  EXPECT_EQ(client.lastDevices()->devices[0].hand, HandSide::Right);

  // Tracking: the fake's closures reach closures(), and through a pose-driven hand the fingertip.
  ASSERT_TRUE(waitFor([&] { return client.closures() && near((*client.closures())[1], 0.1f, kByte); }));
  Forces c = *client.closures();
  EXPECT_NEAR(c[0], 0.2f, kByte);
  EXPECT_NEAR(c[2], 0.3f, kByte);
  EXPECT_EQ(c[3], 0.0f);  // a G1 does not track ring and little
  EXPECT_EQ(c[4], 0.0f);

  World world;
  HandFrame frame;
  frame.pose.wrist.translation() = Vec3(0, 1, 0);  // in the air
  frame.pose.closure = c;
  HapticSession session(world, {}, frame);
  session.step(frame);
  const Vec3 open = session.rig().target(Finger::Index);
  EXPECT_LT((open - fingertipPosition(session.rig().settings().geometry, frame.pose, Finger::Index)).norm(), 1e-5f);
  indexClosure.store(0.9f);
  ASSERT_TRUE(waitFor([&] { return near((*client.closures())[1], 0.9f, kByte); }));
  frame.pose.closure = *client.closures();
  session.step(frame);
  const Vec3 closed = session.rig().target(Finger::Index);
  EXPECT_GT((closed - open).norm(), 0.02f) << "the tracked index closure moves the virtual fingertip";
  EXPECT_LT((closed - fingertipPosition(session.rig().settings().geometry, frame.pose, Finger::Index)).norm(), 1e-5f);

  // Forces: latched, sent once per change; 0 becomes one stopForce.
  Clock::time_point t0 = Clock::now();
  sim.set({0.0f, 0.5f, 0.25f, 0.7f, 0.7f});
  ASSERT_TRUE(waitFor([&] {
    return fake.latchedForce(HandSide::Right, Point::Index) == 0.5f &&
           fake.latchedForce(HandSide::Right, Point::Middle) == 0.25f;
  }));
  std::this_thread::sleep_for(150ms);  // ~150 more publishes of the same values
  EXPECT_EQ(commandsOf(fake, Kind::Force, Point::Index, t0).size(), 1u);
  EXPECT_EQ(commandsOf(fake, Kind::Force, Point::Middle, t0).size(), 1u);
  EXPECT_TRUE(commandsOf(fake, Kind::Force, Point::Thumb).empty());
  EXPECT_EQ(commandsOf(fake, Kind::StopForce, Point::Thumb).size(), 1u);  // the session starts released
  EXPECT_TRUE(commandsOf(fake, Kind::Force, Point::Annular).empty()) << "not a G1 thimble";
  EXPECT_TRUE(commandsOf(fake, Kind::StopForce, Point::Pinky).empty());

  t0 = Clock::now();
  sim.set({0.0f, 0.0f, 0.25f, 0.0f, 0.0f});
  ASSERT_TRUE(waitFor([&] { return fake.latchedForce(HandSide::Right, Point::Index) == 0.0f; }));
  std::this_thread::sleep_for(150ms);
  EXPECT_EQ(commandsOf(fake, Kind::StopForce, Point::Index, t0).size(), 1u);
  EXPECT_TRUE(commandsOf(fake, Kind::Force, Point::Index, t0).empty());
  EXPECT_TRUE(commandsOf(fake, Kind::Force, Point::Middle, t0).empty());

  // Out of range and NaN never reach the wire.
  sim.set({2.0f, std::numeric_limits<float>::quiet_NaN(), -1.0f, 0.0f, 0.0f});
  ASSERT_TRUE(waitFor([&] {
    return fake.latchedForce(HandSide::Right, Point::Thumb) == 1.0f &&
           fake.latchedForce(HandSide::Right, Point::Middle) == 0.0f;
  }));
  EXPECT_EQ(fake.latchedForce(HandSide::Right, Point::Index), 0.0f);
  for (const ReceivedCommand& r : fake.commands()) {
    EXPECT_TRUE(std::isfinite(r.command.value) && r.command.value >= 0.0f && r.command.value <= 1.0f)
        << describe(r.command);
  }
  EXPECT_EQ(fake.malformedFrames(), 0u);

  const Stats stats = client.stats();
  EXPECT_GT(stats.framesSent, 5u);
  EXPECT_GT(stats.framesReceived, 10u);
  EXPECT_EQ(stats.malformedFrames, 0u);
  EXPECT_EQ(stats.reconnects, 0u);
  EXPECT_EQ(stats.watchdogTrips, 0u);
  collect();
  EXPECT_EQ(countEvents(events, "connected", false), 1u) << listed(events);
  EXPECT_EQ(countEvents(events, "calibrat", false), 2u) << listed(events);  // calibrating, calibrated
  EXPECT_EQ(std::count_if(events.begin(), events.end(), [](const Event& e) { return e.error; }), 0) << listed(events);

  sim.stop();
  client.shutdown();
  EXPECT_TRUE(latchedAll(fake, 0.0f));
  EXPECT_EQ(commandsOf(fake, Kind::Stop).size(), 1u);
  EXPECT_EQ(client.state(), State::Disconnected);
}

TEST(WeartClient, ProGloveLeftHandFiveThimbles) {
  FakeMiddlewareSettings fs;
  fs.pro = true;
  fs.hands = {HandSide::Left};
  fs.tracking = [](double) { return Forces{0.1f, 0.2f, 0.3f, 0.7f, 0.35f}; };
  FakeMiddleware fake(fs);
  fake.start();
  ClientSettings cs = settingsFor(fake);
  cs.hand = HandSide::Left;
  cs.thimbles = {Point::Thumb, Point::Index, Point::Middle, Point::Annular, Point::Pinky};
  Client client(cs);
  client.start();
  Publisher sim(client, {0.0f, 0.0f, 0.0f, 0.6f, 0.2f});
  ASSERT_TRUE(waitFor([&] { return client.closures().has_value(); }));
  const Forces c = *client.closures();
  const Forces expected{0.1f, 0.2f, 0.3f, 0.7f, 0.35f};
  for (int f = 0; f < kFingerCount; ++f) EXPECT_NEAR(c[std::size_t(f)], expected[std::size_t(f)], 1e-3f) << f;
  ASSERT_TRUE(waitFor([&] {
    return fake.latchedForce(HandSide::Left, Point::Annular) == 0.6f &&
           fake.latchedForce(HandSide::Left, Point::Pinky) == 0.2f;
  }));
  ASSERT_TRUE(client.lastStatus());
  EXPECT_TRUE(client.lastStatus()->pro);
  ASSERT_TRUE(client.lastDevices());
  EXPECT_TRUE(client.lastDevices()->pro);
  EXPECT_EQ(fake.latchedForce(HandSide::Right, Point::Annular), 0.0f);
  for (const ReceivedCommand& r : fake.commands()) {
    if (r.command.kind == Kind::Force || r.command.kind == Kind::StopForce) {
      EXPECT_EQ(r.command.hand, HandSide::Left);
    }
  }
  sim.stop();
  client.shutdown();
  for (Point p : cs.thimbles) EXPECT_EQ(fake.latchedForce(HandSide::Left, p), 0.0f) << wireName(p);
}

TEST(WeartClient, TrackingScriptDrivesClosures) {
  FakeMiddlewareSettings fs;
  fs.tracking = TrackingScript::parse("0 0 0 0\n0.2 0.4 0.6 0.8\n").source();
  FakeMiddleware fake(fs);
  fake.start();
  ClientSettings cs = settingsFor(fake);
  cs.calibrate = false;
  cs.watchdog = 60s;  // no publisher here
  Client client(cs);
  client.start();
  ASSERT_TRUE(waitFor([&] { return client.closures() && near((*client.closures())[2], 0.8f, kByte); }));
  const Forces c = *client.closures();
  EXPECT_NEAR(c[0], 0.4f, kByte);
  EXPECT_NEAR(c[1], 0.6f, kByte);
  EXPECT_TRUE(commandsOf(fake, Kind::StartCalibration).empty());
  EXPECT_GT(fake.trackingFramesSent(), 0u);
}

TEST(WeartClient, ResendsLatchedStateAfterReconnect) {
  FakeMiddleware fake;
  fake.start();
  Client client(settingsFor(fake));
  client.start();
  Publisher sim(client, {0.3f, 0.6f, 0.9f, 0.0f, 0.0f});
  client.setTemperature(Point::Index, 0.8f);
  client.setTexture(Point::Middle, Texture{9, 0.4f, 80.0f});
  auto allLatched = [&] {
    return fake.latchedForce(HandSide::Right, Point::Thumb) == 0.3f &&
           fake.latchedForce(HandSide::Right, Point::Index) == 0.6f &&
           fake.latchedForce(HandSide::Right, Point::Middle) == 0.9f &&
           fake.latched(HandSide::Right, Point::Index).temperature == 0.8f &&
           fake.latched(HandSide::Right, Point::Middle).texture == 9;
  };
  ASSERT_TRUE(waitFor([&] { return allLatched() && client.state() == State::Running; }));  // calibrated
  EXPECT_FALSE(fake.latched(HandSide::Right, Point::Thumb).temperature);
  EXPECT_EQ(fake.connections(), 1);

  fake.dropClient();  // the new session starts from a released glove: the client must resend
  ASSERT_TRUE(waitFor([&] { return fake.connections() == 2 && client.state() == State::Running; }));
  ASSERT_TRUE(waitFor(allLatched));
  for (Point p : kG1) {
    bool resent = false;
    for (const ReceivedCommand& r : commandsOf(fake, Kind::Force, p)) resent |= r.connection == 2;
    EXPECT_TRUE(resent) << wireName(p);
  }
  EXPECT_EQ(client.stats().reconnects, 1u);
  EXPECT_EQ(commandsOf(fake, Kind::StartCalibration).size(), 1u) << "calibration runs once per client";

  // Releasing temperature and texture sends their stop once.
  client.setTemperature(Point::Index, std::nullopt);
  client.setTexture(Point::Middle, std::nullopt);
  ASSERT_TRUE(waitFor([&] {
    return !fake.latched(HandSide::Right, Point::Index).temperature &&
           !fake.latched(HandSide::Right, Point::Middle).texture;
  }));
  const std::vector<Event> events = client.takeEvents();
  EXPECT_EQ(countEvents(events, "connection", true), 1u) << listed(events);
  EXPECT_EQ(countEvents(events, "connected", false), 2u) << listed(events);
  sim.stop();
  client.shutdown();
  EXPECT_TRUE(latchedAll(fake, 0.0f));
}

TEST(WeartClient, WatchdogReleasesTheGloveWhenTheSimulationStalls) {
  FakeMiddleware fake;
  fake.start();
  ClientSettings cs = settingsFor(fake);
  cs.watchdog = ClientSettings{}.watchdog;
  ASSERT_EQ(cs.watchdog, 50ms);
  Client client(cs);
  client.start();
  const Forces pressing{0.5f, 0.5f, 0.5f, 0.0f, 0.0f};
  std::uint64_t tripsBefore = 0;
  Clock::time_point lastPublish;
  for (int attempt = 0;; ++attempt) {  // again if this thread was held up 50 ms while pressing
    ASSERT_LT(attempt, 5);
    ASSERT_TRUE(waitFor([&] { return latchedAll(fake, 0.5f); }, [&] { client.publishForces(pressing); }));
    tripsBefore = client.stats().watchdogTrips;
    for (int i = 0; i < 20; ++i) {
      client.publishForces(pressing);
      std::this_thread::sleep_for(1ms);
    }
    client.publishForces(pressing);
    lastPublish = Clock::now();
    if (client.stats().watchdogTrips == tripsBefore && latchedAll(fake, 0.5f)) break;
  }
  client.takeEvents();

  // The simulation stalls: every thimble gets stopForce.
  ASSERT_TRUE(waitFor([&] {
    return std::all_of(kG1.begin(), kG1.end(),
                       [&](Point p) { return !commandsOf(fake, Kind::StopForce, p, lastPublish).empty(); });
  }));
  Clock::duration delay{};
  for (Point p : kG1)
    delay = std::max(delay, commandsOf(fake, Kind::StopForce, p, lastPublish).front().time - lastPublish);
  const double ms = std::chrono::duration<double, std::milli>(delay).count();
  vrd::testing::record("watchdog_release_ms", ms);
  std::printf("watchdog: glove released %.1f ms after the last publish (limit 50 ms)\n", ms);
  EXPECT_GE(ms, 50.0);
  EXPECT_LT(ms, 500.0);
  EXPECT_TRUE(latchedAll(fake, 0.0f));
  EXPECT_EQ(client.stats().watchdogTrips, tripsBefore + 1);
  std::vector<Event> events = client.takeEvents();
  EXPECT_EQ(countEvents(events, "simulation stalled: glove released", true), 1u) << listed(events);

  // Publishing again restores the forces.
  ASSERT_TRUE(waitFor([&] { return latchedAll(fake, 0.5f); }, [&] { client.publishForces(pressing); }));
  events = client.takeEvents();
  EXPECT_EQ(countEvents(events, "resumed", false), 1u) << listed(events);
}

TEST(WeartClient, ShutdownReleasesEveryThimble) {
  FakeMiddleware fake;
  fake.start();
  Client client(settingsFor(fake));
  client.start();
  Publisher sim(client, {0.4f, 0.4f, 0.4f, 0.0f, 0.0f});
  client.setTemperature(Point::Thumb, 0.9f);
  client.setRawData(true);
  ASSERT_TRUE(waitFor([&] {
    return latchedAll(fake, 0.4f) && fake.latched(HandSide::Right, Point::Thumb).temperature && fake.rawDataOn();
  }));
  const Clock::time_point before = Clock::now();
  client.shutdown();  // the simulation is still publishing
  const double seconds = std::chrono::duration<double>(Clock::now() - before).count();
  vrd::testing::record("shutdown_s", seconds);
  EXPECT_LT(seconds, 3.0);
  EXPECT_TRUE(latchedAll(fake, 0.0f));
  EXPECT_FALSE(fake.latched(HandSide::Right, Point::Thumb).temperature);
  EXPECT_FALSE(fake.rawDataOn());
  const std::vector<ReceivedCommand> stops = commandsOf(fake, Kind::Stop);
  ASSERT_EQ(stops.size(), 1u);
  for (Point p : kG1) {
    const std::vector<ReceivedCommand> released = commandsOf(fake, Kind::StopForce, p, before);
    ASSERT_FALSE(released.empty()) << wireName(p);
    EXPECT_LE(released.back().time, stops[0].time);
  }
  EXPECT_EQ(client.state(), State::Disconnected);
  client.shutdown();  // idempotent
  sim.stop();
  EXPECT_TRUE(waitFor([&] { return !fake.clientConnected(); }));
}

TEST(WeartClient, DestroyedByAnExceptionReleasesTheGlove) {
  FakeMiddleware fake;
  fake.start();
  try {
    Client client(settingsFor(fake));
    client.start();
    const Forces pressing{0.8f, 0.8f, 0.8f, 0.0f, 0.0f};
    ASSERT_TRUE(waitFor([&] { return latchedAll(fake, 0.8f); }, [&] { client.publishForces(pressing); }));
    throw std::runtime_error("the simulation failed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_TRUE(latchedAll(fake, 0.0f));
  EXPECT_EQ(commandsOf(fake, Kind::Stop).size(), 1u);
}

TEST(WeartClient, StopSignalEndsTheLoopAndReleasesTheGlove) {
  FakeMiddleware fake;
  fake.start();
  int signal = 0;
  {
    StopSignals signals;
    Client client(settingsFor(fake));
    client.start();
    const Clock::time_point until = Clock::now() + kWait;
    bool raised = false;
    while (!signals.requested()) {  // the application's loop
      client.publishForces({0.7f, 0.7f, 0.7f, 0.0f, 0.0f});
      if (!raised && latchedAll(fake, 0.7f)) {
        std::raise(SIGTERM);
        raised = true;
      }
      ASSERT_TRUE(Clock::now() < until) << "no signal seen";
      std::this_thread::sleep_for(1ms);
    }
    signal = signals.signal();
  }  // destructors: the client releases the glove, the handlers are restored
  EXPECT_EQ(signal, SIGTERM);
  EXPECT_TRUE(latchedAll(fake, 0.0f));
  EXPECT_EQ(commandsOf(fake, Kind::Stop).size(), 1u);
}

extern "C" void testSignalHandler(int) {}

TEST(StopSignals, RestoresThePreviousHandlersAndIsUnique) {
  struct sigaction mine {
  }, old{};
  mine.sa_handler = testSignalHandler;
  sigemptyset(&mine.sa_mask);
  ASSERT_EQ(::sigaction(SIGINT, &mine, &old), 0);
  {
    StopSignals signals;
    EXPECT_FALSE(signals.requested());
    EXPECT_NE(vrd::testing::errorOf([] { StopSignals second; }).find("already"), std::string::npos);
    struct sigaction now {};
    ::sigaction(SIGINT, nullptr, &now);
    EXPECT_NE(now.sa_handler, testSignalHandler);
    std::raise(SIGINT);
    EXPECT_TRUE(signals.requested());
    EXPECT_EQ(signals.signal(), SIGINT);
  }
  struct sigaction after {};
  ::sigaction(SIGINT, &old, &after);
  EXPECT_EQ(after.sa_handler, testSignalHandler);
  StopSignals again;  // a new instance starts cleared
  EXPECT_FALSE(again.requested());
}

TEST(WeartClient, SurvivesGarbageFromTheMiddleware) {
  FakeMiddleware fake;
  fake.start();
  ClientSettings cs = settingsFor(fake);
  Client client(cs);
  client.start();
  Publisher sim(client, {0.2f, 0.2f, 0.2f, 0.0f, 0.0f});
  ASSERT_TRUE(waitFor([&] { return latchedAll(fake, 0.2f) && client.state() == State::Running; }));

  fake.sendRaw("Tracking:TrackType1:1:2~");                   // wrong field count
  fake.sendRaw("{\"type\":\"MW_STATUS\",\"ts\":~");           // broken JSON
  fake.sendRaw("\x80\xff\xfe\x01~");                          // not ASCII
  fake.sendRaw("CalibrationResult:7:0~force:abc~~~ ~\r\n~");  // bad hand; empty frames are not frames
  fake.sendRaw("SOMETHING_NEW:1:2~");                         // unknown ID: ignored, not malformed
  std::string overLong((1 << 20) + 100, 'a');
  overLong += '~';         // (appended, not added: GCC 12 warns about std::string + "~" here, wrongly)
  fake.sendRaw(overLong);  // over-long: dropped by the splitter
  MiddlewareStatus status;
  status.status = "RUNNING";
  status.version = "9.9.9-split";
  status.connectedDevices.push_back({"FA:KE:00:00:00:02", HandSide::Right});
  const std::string whole = statusFrame(status, 1717600000000);
  fake.sendSplit(whole, 17);  // one frame in two writes
  ASSERT_TRUE(waitFor([&] { return client.lastStatus() && client.lastStatus()->version == "9.9.9-split"; }));
  // Wrong field count, broken JSON, non-ASCII, bad hand, over-long; nothing else.
  EXPECT_EQ(client.stats().malformedFrames, 5u);

  EXPECT_EQ(fake.connections(), 1);
  EXPECT_EQ(client.state(), State::Running);
  sim.set({0.6f, 0.6f, 0.6f, 0.0f, 0.0f});
  ASSERT_TRUE(waitFor([&] { return latchedAll(fake, 0.6f); }));
  const std::vector<Event> events = client.takeEvents();
  EXPECT_EQ(std::count_if(events.begin(), events.end(), [](const Event& e) { return e.error; }), 0) << listed(events);
}

TEST(WeartClient, StartErrorIsReportedOnce) {
  FakeMiddleware fake;
  fake.setStartError(101);
  fake.start();
  ClientSettings cs = settingsFor(fake);
  cs.retryMax = 60ms;
  cs.watchdog = 60s;
  Client client(cs);
  client.start();
  ASSERT_TRUE(waitFor([&] { return commandsOf(fake, Kind::Start).size() >= 4; }));  // refused, retried
  EXPECT_NE(client.state(), State::Running);
  ASSERT_TRUE(client.lastStatus());
  EXPECT_EQ(client.lastStatus()->statusCode, 101);
  fake.setStartError(0);
  ASSERT_TRUE(waitFor([&] { return client.state() == State::Running; }));
  const std::vector<Event> events = client.takeEvents();
  EXPECT_EQ(countEvents(events, "101", true), 1u) << listed(events);
  EXPECT_EQ(countEvents(events, "error", true), 1u) << listed(events);
  EXPECT_GE(countEvents(events, "running", false), 1u) << listed(events);
  EXPECT_EQ(fake.connections(), 1);
}

TEST(WeartClient, CalibrationFailureIsReportedAndTheSessionRuns) {
  FakeMiddlewareSettings fs;
  fs.calibrationSucceeds = false;
  FakeMiddleware fake(fs);
  fake.start();
  Client client(settingsFor(fake));
  client.start();
  Publisher sim(client, {0.0f, 0.3f, 0.0f, 0.0f, 0.0f});
  ASSERT_TRUE(waitFor([&] {
    return client.state() == State::Running && fake.latchedForce(HandSide::Right, Point::Index) == 0.3f &&
           !commandsOf(fake, Kind::StopCalibration).empty();
  }));
  EXPECT_EQ(commandsOf(fake, Kind::StopCalibration).size(), 1u);
  const std::vector<Event> events = client.takeEvents();
  EXPECT_EQ(countEvents(events, "calibration failed", true), 1u) << listed(events);
  EXPECT_EQ(countEvents(events, "uncalibrated", false), 1u) << listed(events);
}

TEST(WeartClient, ExitAndDisconnectMakeTheClientReconnect) {
  FakeMiddleware fake;
  fake.start();
  Client client(settingsFor(fake));
  client.start();
  Publisher sim(client, {0.5f, 0.0f, 0.0f, 0.0f, 0.0f});
  ASSERT_TRUE(waitFor([&] { return fake.latchedForce(HandSide::Right, Point::Thumb) == 0.5f; }));
  fake.sendExit();
  ASSERT_TRUE(waitFor([&] { return fake.connections() == 2 && client.state() == State::Running; }));
  bool stoppedFirst = false;  // §4 rule 7: StopFromClient before closing
  for (const ReceivedCommand& r : commandsOf(fake, Kind::Stop)) stoppedFirst |= r.connection == 1;
  EXPECT_TRUE(stoppedFirst);
  ASSERT_TRUE(waitFor([&] { return fake.latchedForce(HandSide::Right, Point::Thumb) == 0.5f; }));
  fake.sendDisconnect();
  ASSERT_TRUE(waitFor([&] { return fake.connections() == 3 && client.state() == State::Running; }));
  ASSERT_TRUE(waitFor([&] { return fake.latchedForce(HandSide::Right, Point::Thumb) == 0.5f; }));
  EXPECT_EQ(client.stats().reconnects, 2u);
}

TEST(WeartClient, ReportsAnAbsentMiddlewareOnceAndConnectsWhenItAppears) {
  std::uint16_t port = 0;
  {
    FakeMiddleware probe;  // a free port, then nobody listening there
    port = probe.port();
  }
  ClientSettings cs;
  cs.port = port;
  cs.retryMin = 10ms;
  cs.retryMax = 40ms;
  cs.watchdog = 60s;
  Client client(cs);
  client.start();
  std::vector<Event> events;
  ASSERT_TRUE(waitFor([&] {
    for (Event& e : client.takeEvents()) events.push_back(std::move(e));
    return events.size() >= 1;
  }));
  std::this_thread::sleep_for(300ms);  // several more attempts
  for (Event& e : client.takeEvents()) events.push_back(std::move(e));
  EXPECT_EQ(countEvents(events, "cannot connect", true), 1u) << listed(events);
  EXPECT_EQ(events.size(), 1u) << listed(events);
  EXPECT_NE(client.state(), State::Running);

  FakeMiddlewareSettings fs;
  fs.port = port;
  FakeMiddleware fake(fs);
  fake.start();
  ASSERT_TRUE(waitFor([&] { return client.state() == State::Running; }));
  for (Event& e : client.takeEvents()) events.push_back(std::move(e));
  EXPECT_EQ(countEvents(events, "connected to", false), 1u) << listed(events);
  EXPECT_EQ(client.stats().reconnects, 0u);
}

TEST(WeartClient, RawDataOnAndOff) {
  FakeMiddleware fake;
  fake.start();
  ClientSettings cs = settingsFor(fake);
  cs.watchdog = 60s;
  Client client(cs);
  client.start();
  client.setRawData(true);
  ASSERT_TRUE(waitFor([&] { return fake.rawDataOn(); }));
  const std::uint64_t received = client.stats().framesReceived;
  ASSERT_TRUE(waitFor([&] { return client.stats().framesReceived > received + 20; }));
  EXPECT_EQ(client.stats().malformedFrames, 0u) << "the fake's RAW_DATA frames parse";
  client.setRawData(false);
  ASSERT_TRUE(waitFor([&] { return !fake.rawDataOn(); }));
  EXPECT_EQ(commandsOf(fake, Kind::Request).size(), 4u);  // two status requests, on, off
}

TEST(WeartClient, SlowMiddlewareNeverBlocksPublishing) {
  FakeMiddlewareSettings fs;
  fs.receiveBuffer = 4096;
  FakeMiddleware fake(fs);
  fake.start();
  Client client(settingsFor(fake));
  client.start();
  Forces f{0.1f, 0.1f, 0.1f, 0.0f, 0.0f};
  ASSERT_TRUE(waitFor([&] { return latchedAll(fake, 0.1f); }, [&] { client.publishForces(f); }));

  fake.setReadDelay(30ms);  // reads 256 bytes every 30 ms: the client's socket fills up
  std::vector<double> us;
  const Clock::time_point until = Clock::now() + 1s;
  for (int i = 0; Clock::now() < until; ++i) {
    f.fill(float(i % 97) / 100.0f + 0.01f);  // a new value every call: frames to send all the time
    const Clock::time_point t = Clock::now();
    client.publishForces(f);
    us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t).count());
    std::this_thread::sleep_for(200us);
  }
  std::sort(us.begin(), us.end());
  const double median = us[us.size() / 2], worst = us.back();
  vrd::testing::record("publish_median_us", median);
  vrd::testing::record("publish_max_us", worst);
  vrd::testing::record("publish_calls", double(us.size()));
  std::printf("publishForces against a slow reader: %zu calls, median %.2f us, max %.1f us\n", us.size(), median,
              worst);
  EXPECT_LT(median, 100.0);
  EXPECT_LT(worst, 20000.0) << "a call waited for the network (the reader sleeps 30 ms)";

  // Once the middleware reads again the newest values arrive (older ones were coalesced).
  fake.setReadDelay(0ms);
  f = {0.42f, 0.42f, 0.42f, 0.0f, 0.0f};
  ASSERT_TRUE(waitFor([&] { return latchedAll(fake, 0.42f); }, [&] { client.publishForces(f); }, 10s));
  EXPECT_EQ(fake.connections(), 1);
}

}  // namespace
}  // namespace vrd::weart
