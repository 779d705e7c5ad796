#pragma once
// The WEART middleware client (TouchDIVER G1 and Pro). One I/O thread owns the TCP connection and
// speaks the protocol of weart_protocol.h; the simulation publishes forces and reads finger
// closures without ever waiting on the network.
//
// Haptics are latched state (protocol notes §4 rule 5, §6.6): the client remembers what the glove
// has and sends a frame only when that changes, and resends every active effect after a reconnect.
// Safety: a watchdog releases every thimble when the simulation stops publishing, and shutdown()
// (also run by the destructor) releases them before it closes.

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vrdeform/devices/weart_protocol.h"
#include "vrdeform/interact/hand.h"

namespace vrd::weart {

struct ClientSettings {
  std::string host = "127.0.0.1";  ///< middleware host: a name, an IPv4 or an IPv6 address
  std::uint16_t port = 13031;      ///< middleware TCP port (§2)
  HandSide hand = HandSide::Right;
  /// Points that get haptics: the G1's three thimbles; a Pro adds Annular and Pinky.
  std::vector<Point> thimbles{Point::Thumb, Point::Index, Point::Middle};
  /// Run the tracking calibration once the session is running: once per Client (again on the next
  /// connection only if it did not finish).
  bool calibrate = true;
  /// Longest gap between publishForces() calls before every thimble is released.
  std::chrono::milliseconds watchdog{50};
  std::chrono::milliseconds connectTimeout{1000};  ///< per connection attempt
  std::chrono::milliseconds retryMin{250};         ///< first wait before reconnecting / restarting
  std::chrono::milliseconds retryMax{5000};        ///< the wait doubles up to this
};

/// "HOST:PORT", "HOST", ":PORT" or "[IPv6]:PORT" (an IPv6 address without a port may also be given
/// bare, "::1"); what is left out keeps its value from `base`. Throws vrd::Error on anything else.
ClientSettings parseEndpoint(std::string_view endpoint, ClientSettings base = {});

/// The glove point of a finger: Thumb, Index, Middle, then Ring -> Annular, Little -> Pinky.
Point pointOf(Finger finger);

struct Texture {
  int index = 0;          ///< 0-21 (§6.5); anything else is the null texture 255
  float velocity = 0.0f;  ///< [0, 0.5]
  float volume = 100.0f;  ///< [0, 100]
};

enum class State : std::uint8_t {
  Disconnected,  ///< no connection (waiting to retry)
  Connecting,    ///< TCP connect in progress
  Idle,          ///< connected; the session is not started (or waits to restart)
  Starting,      ///< StartFromClient sent, waiting for RUNNING
  Running,       ///< haptics and tracking flow
  Calibrating,   ///< running, tracking calibration in progress
  Stopping,      ///< shutdown: releasing the glove and closing
};
std::string_view toString(State state);

/// Something the user should hear about: a connection change, a middleware error, a stall.
struct Event {
  std::chrono::steady_clock::time_point time;
  std::string message;
  bool error = false;
};

struct Stats {
  std::uint64_t framesSent = 0;       ///< frames queued on the connection (sent unless it dropped)
  std::uint64_t framesReceived = 0;   ///< well-formed frames received
  std::uint64_t malformedFrames = 0;  ///< frames that could not be parsed (or over-long ones dropped)
  std::uint64_t reconnects = 0;       ///< connections made after the first
  std::uint64_t watchdogTrips = 0;    ///< times the watchdog released the glove
};

/// Thread safety: start() and shutdown() belong to the owner. Every other member may be called
/// from any thread; none of them waits on I/O (each holds a mutex for a small copy at most).
class Client {
 public:
  /// Validates the settings (throws vrd::Error); no I/O yet.
  explicit Client(ClientSettings settings);
  /// shutdown().
  ~Client();
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  /// Spawns the I/O thread and returns at once; it connects, starts the session, calibrates when
  /// asked to, and reconnects with exponential back-off whenever the connection drops. A second
  /// call does nothing; a call after shutdown() throws vrd::Error.
  void start();
  /// Releases every configured thimble (stopForce; stopTemperature / stopTexture where active),
  /// sends StopFromClient, closes and joins the I/O thread. Idempotent; takes at most about 2 s
  /// (plus the rest of a host-name lookup in progress, which cannot be interrupted).
  void shutdown() noexcept;

  /// The force per finger, normalised to [0, 1] (clamped; NaN reads 0). Fingers whose point is not
  /// among the thimbles are ignored. A changed force wakes the I/O thread, so its frame leaves at
  /// once. Call it every simulation step: the watchdog releases the glove when it has not been
  /// called for `watchdog`.
  void publishForces(const std::array<float, kFingerCount>& force);
  /// Latest closures of this hand's fingers in [0, 1]; fingers the glove does not track (ring and
  /// little on a G1) read 0. nullopt until the first tracking frame for this hand.
  std::optional<std::array<float, kFingerCount>> closures() const;
  State state() const;
  std::optional<MiddlewareStatus> lastStatus() const;
  std::optional<DevicesStatus> lastDevices() const;
  /// Events since the last call (at most the newest 256 are kept).
  std::vector<Event> takeEvents();
  /// Thermal actuator of a thimble: [0, 1], 0.5 neutral; nullopt (or NaN) releases it.
  void setTemperature(Point point, std::optional<float> value);
  /// Vibrotactile texture of a thimble; nullopt releases it.
  void setTexture(Point point, std::optional<Texture> texture);
  /// Asks the middleware for the raw IMU stream (RAW_DATA_ON / RAW_DATA_OFF); the data is ignored.
  void setRawData(bool on);
  Stats stats() const;
  const ClientSettings& settings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vrd::weart
