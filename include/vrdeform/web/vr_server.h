#pragma once
// The VR server (`vrdeform serve`): one port serves the page (static files), a status document
// and a WebSocket, over TLS when given a certificate. Every viewer gets the scene and its topology once, then a frame
// per new snapshot at display rate; a viewer's controller or tracked hand drives the simulation's hand.
//
// One I/O thread does all of the networking and reads the loop's snapshots through its own
// channel; the loop never waits for it, nor it for a viewer. Each viewer has at most one frame in
// flight: a slow one skips frames (it always gets the newest state) instead of queueing them.
// Hostile input (oversized or malformed messages, floods, wrong types, bad HTTP) is rejected with a
// logged reason, and a viewer that keeps at it is disconnected. docs/vr.md has the protocol.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "vrdeform/interact/live_hand_input.h"
#include "vrdeform/scene/simulation_loop.h"
#include "vrdeform/web/tls_identity.h"
#include "vrdeform/web/vr_protocol.h"
#include "vrdeform/web/xr_hand.h"

namespace vrd {

struct VrServerSettings {
  std::string bind = "127.0.0.1";           ///< address to listen on ("0.0.0.0": every IPv4 interface)
  std::uint16_t port = 8080;                ///< 0: any free port (port() tells which)
  double frameRate = 72.0;                  ///< frames per second at most (Quest 2: 72, 90 or 120 Hz)
  std::size_t maxMessageBytes = 64 * 1024;  ///< larger incoming WebSocket messages close the connection
  double messagesPerSecond = 200.0;         ///< sustained incoming rate per viewer (display rate is ~72-120)
  double messageBurst = 100.0;              ///< messages a viewer may send at once above that rate
  int maxStrikes = 20;                      ///< rejected messages before a viewer is disconnected
  std::size_t maxViewers = 16;              ///< WebSocket connections at once; more are refused (503)
  double stalledWriteSeconds = 10.0;        ///< a viewer that takes longer to accept a frame is dropped
  XrHandSettings hand;                      ///< how viewers' input becomes the hand
  /// A glove's finger closure, used instead of the controller's trigger (called on the I/O thread;
  /// must not block); null or nullopt: the trigger.
  std::function<std::optional<float>()> gloveClosure;
  /// Whether a glove receives the forces (pages then leave their controllers' vibration off).
  std::function<bool()> gloveConnected;
  /// Serve HTTPS and WSS with this certificate instead of HTTP and WS (tls_identity.h).
  std::optional<TlsIdentity> tls;
  /// What participants do on a study's panel (setPanel), called on the I/O thread (must not block);
  /// null: study messages are rejected.
  std::function<void(const vr::StudyReply&)> onStudy;
  /// Where log lines go (connections, rejected input); default: stderr.
  std::function<void(std::string_view)> log;
};

/// Counters since start(), readable from any thread.
struct VrServerStats {
  std::uint64_t viewers = 0;           ///< WebSocket connections open now
  std::uint64_t viewersTotal = 0;      ///< accepted since start
  std::uint64_t viewersRefused = 0;    ///< over maxViewers
  std::uint64_t framesSent = 0;        ///< frames written to viewers (all viewers together)
  std::uint64_t framesSkipped = 0;     ///< frames a slow viewer never got because a newer one replaced them
  std::uint64_t bytesSent = 0;         ///< WebSocket payload bytes
  std::uint64_t maxInFlightBytes = 0;  ///< the largest message one viewer had in flight
  std::uint64_t messagesReceived = 0;  ///< WebSocket messages accepted
  std::uint64_t messagesRejected = 0;  ///< malformed, wrong type, over the rate or too large
  std::uint64_t viewersDropped = 0;    ///< disconnected for abuse or a stalled write
  std::uint64_t inputs = 0;            ///< input messages that drove the hand
  std::uint64_t httpRequests = 0;      ///< HTTP requests answered (files, status, errors)
  std::uint64_t httpErrors = 0;        ///< of those, answered with 4xx / 5xx
  std::uint64_t snapshots = 0;         ///< new snapshots the server has taken from the loop
  std::uint64_t viewersBehind = 0;     ///< viewers skipping frames now (a newer one waits for their write)
};

class VrServer {
 public:
  /// Serves `scene` while `loop` runs it (both must outlive the server, or a later show()) from the
  /// web folder `web` (webFolder()). `hand`, when given, is the loop's input and follows the viewers'
  /// hands; null: viewers only watch. The loop must not have started: its world as it is now is the
  /// viewers' first frame. Binds nothing yet.
  VrServer(SimulationLoop& loop, const BuiltScene& scene, std::filesystem::path web, VrServerSettings settings,
           LiveHandInput* hand = nullptr);
  /// stop().
  ~VrServer();
  VrServer(const VrServer&) = delete;
  VrServer& operator=(const VrServer&) = delete;

  /// Binds and starts the I/O thread. Throws vrd::Error for a bad address or a port in use.
  void start();
  /// Closes every connection (going away) and joins the I/O thread; idempotent.
  void stop();
  /// Shows another scene from now on, as the constructor's (the loop not started yet): every viewer
  /// gets its scene message and topology anew; the hand waits at `park` (XrHandSettings::park)
  /// while no viewer drives it. Returns once the server has let go of the previous scene, loop and
  /// hand, which may then be destroyed. From the thread that starts and stops the server.
  void show(SimulationLoop& loop, const BuiltScene& scene, LiveHandInput* hand, const Vec3& park);
  /// A study's panel (a "study" JSON message, docs/vr.md#study): sent to every viewer now and to
  /// each one that connects later; empty: none.
  void setPanel(std::string json);
  /// The port listened on (after start()).
  std::uint16_t port() const;
  VrServerStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vrd
