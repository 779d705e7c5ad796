#pragma once
// A fake WEART middleware (protocol notes §11) for tests and for trying the client without a
// glove: a TCP server on 127.0.0.1 with its own thread, one client at a time. It pushes the status
// and device status on connect and every statusPeriod, the status also on every change (clients
// such as the vendor's examples listen without asking), answers status requests, starts,
// calibrates and stops sessions, streams tracking while running (G1 `Tracking`, DEFAULT after a
// bare start, or Pro `TRACKING_BENDING_G2`) and, after RAW_DATA_ON, raw data of every node, and
// records every client command with the force each thimble would press now. Test hooks break it
// on purpose.

#include <array>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vrdeform/devices/weart_protocol.h"
#include "vrdeform/interact/hand.h"

namespace vrd::weart {

/// Finger closures over time (seconds since the session started), per Finger, in [0, 1].
using TrackingSource = std::function<std::array<float, kFingerCount>(double seconds)>;

/// Keyframes "t thumb index middle [ring little]" (one per line, '#' starts a comment, times
/// strictly increasing, closures in [0, 1]), interpolated linearly and held before the first and
/// after the last. Ring and little default to the middle finger's closure.
class TrackingScript {
 public:
  struct Key {
    double time = 0.0;
    std::array<float, kFingerCount> closure{};
  };
  /// Throws vrd::Error naming `name` and the line.
  static TrackingScript parse(std::string_view text, std::string_view name = "tracking script");
  static TrackingScript load(const std::filesystem::path& path);

  std::array<float, kFingerCount> at(double seconds) const;
  const std::vector<Key>& keys() const { return keys_; }
  /// A TrackingSource that plays this script.
  TrackingSource source() const;

 private:
  std::vector<Key> keys_;
};

/// A command the fake received, when, and on which connection (1 for the first client).
struct ReceivedCommand {
  std::chrono::steady_clock::time_point time;
  int connection = 0;
  ClientCommand command;
};
/// One line for a log: "force RIGHT INDEX 0.5", "StartFromClient TrackType1", "MW_GET_STATUS", ...
std::string describe(const ClientCommand& command);

/// What an actuator is doing now, from the haptic commands received (stop* clears).
struct Latched {
  float force = 0.0f;
  std::optional<float> temperature;
  std::optional<int> texture;  ///< texture index
};

struct FakeMiddlewareSettings {
  std::uint16_t port = 0;  ///< 0: a free port (see port())
  bool pro = false;        ///< WeArtApp + TouchDIVER Pro flavour: WA_STATUS, WEART_TD_PRO_STATUS, TRACKING_BENDING_G2
  std::vector<HandSide> hands{HandSide::Right};  ///< gloves connected to the fake
  double trackingHz = 100.0;                     ///< tracking (and raw data) frames per second while running
  TrackingSource tracking;                       ///< empty: every finger open
  /// The status and device status are pushed this often while a client is connected, besides on
  /// connect (both) and on every status change (the status); 0: only then.
  std::chrono::milliseconds statusPeriod{250};
  /// Time between StartCalibration and its result; the result's success.
  std::chrono::milliseconds calibrationTime{20};
  bool calibrationSucceeds = true;
  int receiveBuffer = 0;  ///< SO_RCVBUF of the client sockets in bytes (0: system default)
  /// Called on the fake's thread for every command received (a log); must not call back into the fake.
  std::function<void(const ReceivedCommand&)> onCommand;
  /// Called on the fake's thread for connections, disconnections and malformed frames.
  std::function<void(std::string_view)> onNote;
};

class FakeMiddleware {
 public:
  /// Binds and listens on 127.0.0.1 (throws vrd::Error when it cannot); serves once start()ed.
  explicit FakeMiddleware(FakeMiddlewareSettings settings = {});
  /// stop().
  ~FakeMiddleware();
  FakeMiddleware(const FakeMiddleware&) = delete;
  FakeMiddleware& operator=(const FakeMiddleware&) = delete;

  void start();
  /// Closes the client and the listening socket, joins the thread. Idempotent.
  void stop() noexcept;
  std::uint16_t port() const;

  // --- what happened (thread-safe copies) ---
  std::vector<ReceivedCommand> commands() const;
  /// The actuator state of (hand, point). Reset when a new client connects (a new session starts
  /// from a released glove); kept when a client goes away, so a test sees what it left behind.
  Latched latched(HandSide hand, Point point) const;
  float latchedForce(HandSide hand, Point point) const { return latched(hand, point).force; }
  std::string status() const;  ///< "IDLE", "RUNNING", ...
  int connections() const;     ///< clients accepted so far
  bool clientConnected() const;
  std::uint64_t malformedFrames() const;  ///< client frames parseClientFrame refused
  std::uint64_t trackingFramesSent() const;
  bool rawDataOn() const;

  // --- live changes and test hooks (they take effect on the fake's thread within milliseconds) ---
  void setTracking(TrackingSource source);
  void dropClient();                ///< abrupt close of the current client
  void sendRaw(std::string bytes);  ///< written as is (garbage, packed frames)
  /// Writes bytes[0, at), pauses 10 ms, writes the rest; no tracking frame goes out in between,
  /// so a frame cut in two arrives in two TCP segments but whole.
  void sendSplit(std::string bytes, std::size_t at);
  void setStartError(int statusCode);              ///< answer StartFromClient with this code (0: start normally)
  void setReadDelay(std::chrono::milliseconds d);  ///< a slow reader: sleep this long before each read
  void sendExit();                                 ///< "exit~"
  void sendDisconnect();                           ///< "disconnect~"

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vrd::weart
