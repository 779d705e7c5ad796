#include "vrdeform/web/vr_server.h"

#include <fmt/format.h>
#include <linux/sockios.h>
#include <sys/ioctl.h>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cstdio>
#include <deque>
#include <future>
#include <list>
#include <nlohmann/json.hpp>
#include <thread>
#include <utility>
#include <vector>

#include "tls_front.h"
#include "vrdeform/error.h"
#include "vrdeform/web/static_files.h"
#include "vrdeform/web/vr_protocol.h"

namespace vrd {
namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using Clock = std::chrono::steady_clock;
using Bytes = std::vector<std::uint8_t>;
using json = nlohmann::json;

constexpr std::size_t kMaxControlMessages = 32;  // queued text replies per viewer; more are dropped
constexpr std::size_t kMaxRequestHeader = 8 * 1024;
constexpr int kSendBufferBytes = 64 * 1024;  // per viewer socket (Linux doubles it)
// A viewer gets its next frame only once the kernel holds less than this for it, so that a slow
// one is sent fresh frames rather than a backlog of stale ones.
constexpr std::size_t kMaxUnsentBytes = 16 * 1024;
constexpr auto kHttpTimeout = std::chrono::seconds(15);
constexpr int kLoggedStrikes = 3;  // per viewer; later rejections are only counted

double secondsBetween(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

std::string peerOf(const beast::tcp_stream& stream) {
  beast::error_code ec;
  const tcp::endpoint e = stream.socket().remote_endpoint(ec);
  return ec ? std::string("?") : fmt::format("{}:{}", e.address().to_string(), e.port());
}

// Log lines about other people's input pass through this, so that a flood of bad requests cannot
// flood the log: a burst of 20, then 5 a second; what it holds back is counted in the next line.
class LogLimiter {
 public:
  bool allow() {
    const Clock::time_point now = Clock::now();
    tokens_ = std::min(20.0, tokens_ + 5.0 * secondsBetween(last_, now));
    last_ = now;
    if (tokens_ < 1.0) {
      ++suppressed_;
      return false;
    }
    tokens_ -= 1.0;
    return true;
  }
  std::uint64_t takeSuppressed() { return std::exchange(suppressed_, 0); }

 private:
  double tokens_ = 20.0;
  Clock::time_point last_ = Clock::now();
  std::uint64_t suppressed_ = 0;
};

struct Counters {
  std::atomic<std::uint64_t> viewers{0}, viewersTotal{0}, viewersRefused{0}, framesSent{0}, framesSkipped{0},
      bytesSent{0}, maxInFlightBytes{0}, messagesReceived{0}, messagesRejected{0}, viewersDropped{0}, inputs{0},
      httpRequests{0}, httpErrors{0}, snapshots{0}, viewersBehind{0};
};

void raiseTo(std::atomic<std::uint64_t>& a, std::uint64_t v) {
  std::uint64_t old = a.load(std::memory_order_relaxed);
  while (old < v && !a.compare_exchange_weak(old, v, std::memory_order_relaxed)) {
  }
}

class Viewer;
class HttpSession;

// Everything the server's thread works with; VrServer::Impl is this.
struct Server {
  Server(SimulationLoop& loop, const BuiltScene& scene, std::filesystem::path web, VrServerSettings settings,
         LiveHandInput* hand);

  void present(SimulationLoop& loop, const BuiltScene& scene, LiveHandInput* hand, const Snapshot& first);
  void run();
  void tick();
  void takeSnapshot(const Snapshot& s);
  void onInput(const XrInput& input);
  void log(std::string_view line) const;
  void logLimited(std::string_view line);
  std::string statusJson() const;
  void shutdown();

  std::filesystem::path web;
  VrServerSettings settings;
  // The scene shown (present()).
  SimulationLoop* loop = nullptr;
  const BuiltScene* scene = nullptr;
  LiveHandInput* hand = nullptr;
  float radius = 0.0f;
  std::vector<ViewMesh> meshes;
  std::shared_ptr<SnapshotChannel> channel;

  // I/O thread only from start() on.
  struct BodyFrame {
    vr::QuantBox box;
    std::shared_ptr<const Bytes> block;  // the newest block; shared by the viewers' writes
    std::uint64_t version = 0;           // +1 whenever the block's bytes change
    std::vector<Vec3> positions;
  };
  std::vector<BodyFrame> bodies;
  std::array<std::uint8_t, vr::frame::kHeaderBytes> header{};
  std::uint32_t frameNumber = 0;  // of the newest frame; 0: none yet
  Snapshot latest;                // the fields status.json reports (positions left empty)
  std::shared_ptr<const std::string> sceneJson;
  std::shared_ptr<const Bytes> topology;
  std::shared_ptr<const std::string> panel;  // a study's panel; null: none
  Clock::time_point lastInput{};
  bool driven = false;
  std::optional<XrPose> head;
  std::list<std::weak_ptr<Viewer>> viewers;
  std::list<std::weak_ptr<HttpSession>> httpSessions;
  LogLimiter limiter;
  std::uint64_t nextViewer = 1;
  bool shuttingDown = false;
  Clock::time_point nextTick{};

  std::optional<net::io_context> ioc;
  std::optional<tcp::acceptor> acceptor;
  std::optional<TlsFront> tls;  // with settings.tls: the public port, tunnelling to acceptor's
  std::optional<net::steady_timer> timer;
  std::thread thread;
  std::atomic<bool> ioDone{false};
  std::atomic<std::uint16_t> port{0};
  Counters counters;
};

// --- WebSocket viewers ------------------------------------------------------------------------------

class Viewer : public std::enable_shared_from_this<Viewer> {
 public:
  Viewer(Server& server, beast::tcp_stream&& stream, std::uint64_t id, std::string peer)
      : server_(server), ws_(std::move(stream)), id_(id), peer_(std::move(peer)) {
    sentVersion_.assign(server_.bodies.size(), 0);
    tokens_ = server_.settings.messageBurst;
    lastRefill_ = Clock::now();
  }
  ~Viewer() {
    if (accepted_) server_.counters.viewers.fetch_sub(1, std::memory_order_relaxed);
  }

  void start(http::request<http::empty_body> request) {
    beast::get_lowest_layer(ws_).expires_never();  // the websocket's own timeouts from here on
    // A small kernel buffer: a viewer that falls behind gets fresh frames, not a backlog of stale ones.
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().set_option(net::socket_base::send_buffer_size(kSendBufferBytes), ec);
    websocket::stream_base::timeout timeouts = websocket::stream_base::timeout::suggested(beast::role_type::server);
    timeouts.keep_alive_pings = true;  // an observer that sends nothing stays, as long as it answers pings
    ws_.set_option(timeouts);
    ws_.set_option(websocket::stream_base::decorator(
        [](websocket::response_type& res) { res.set(http::field::server, "vrdeform"); }));
    ws_.read_message_max(server_.settings.maxMessageBytes);
    ws_.auto_fragment(false);
    ws_.async_accept(request, beast::bind_front_handler(&Viewer::onAccept, shared_from_this()));
  }

  // Sends what is due: replies first, then the newest frame; one message in flight at a time.
  void pump() {
    if (writing_ || closing_ || !accepted_) return;
    if (!control_.empty()) {
      Outgoing m = std::move(control_.front());
      control_.pop_front();
      write(std::move(m));
      return;
    }
    if (server_.frameNumber > sentFrame_ && unsentBytes() <= kMaxUnsentBytes) writeFrame();
  }

  // Still sending older data while a newer frame waits: this viewer is skipping frames.
  bool behind() { return server_.frameNumber > sentFrame_ + 1 && (writing_ || unsentBytes() > kMaxUnsentBytes); }

  // A write that does not finish in time: the viewer is gone or not reading. Drop it.
  void checkStalled(Clock::time_point now) {
    if (!writing_ || secondsBetween(writeStart_, now) < server_.settings.stalledWriteSeconds) return;
    server_.logLimited(fmt::format("vr: viewer {} ({}) dropped: a frame took over {:g} s to send", id_, peer_,
                                   server_.settings.stalledWriteSeconds));
    server_.counters.viewersDropped.fetch_add(1, std::memory_order_relaxed);
    abort();
  }

  void close(websocket::close_code code, std::string_view reason) {
    if (!accepted_) return abort();  // still in the handshake
    if (closing_) return;
    closing_ = true;
    ws_.async_close(websocket::close_reason(code, reason), [self = shared_from_this()](beast::error_code) {});
  }

  void abort() {
    closing_ = true;
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().close(ec);
  }

 private:
  // Bytes the kernel still holds for this viewer (sent and not yet acknowledged, or not sent); 0
  // when it cannot tell.
  std::size_t unsentBytes() {
    int n = 0;
    if (::ioctl(beast::get_lowest_layer(ws_).socket().native_handle(), SIOCOUTQ, &n) != 0 || n < 0) return 0;
    return std::size_t(n);
  }

  struct Outgoing {
    std::shared_ptr<const Bytes> binary;
    std::string text;
  };

  void onAccept(beast::error_code ec) {
    if (ec) {
      server_.logLimited(fmt::format("vr: {}: WebSocket handshake failed: {}", peer_, ec.message()));
      return;
    }
    accepted_ = true;
    server_.counters.viewers.fetch_add(1, std::memory_order_relaxed);
    server_.counters.viewersTotal.fetch_add(1, std::memory_order_relaxed);
    server_.logLimited(fmt::format("vr: viewer {} connected from {}", id_, peer_));
    greet();
    pump();
    read();
  }

 public:
  // The scene shown changed: its scene message and topology, then frames of every body.
  void reshow() {
    if (!accepted_ || closing_) return;
    sentVersion_.assign(server_.bodies.size(), 0);
    greet();
    pump();
  }

  void showPanel() {
    if (!accepted_ || closing_ || !server_.panel) return;
    control_.push_back({nullptr, *server_.panel});
    pump();
  }

 private:
  void greet() {
    control_.push_back({nullptr, *server_.sceneJson});
    control_.push_back({server_.topology, {}});
    if (server_.panel) control_.push_back({nullptr, *server_.panel});
  }

  void read() { ws_.async_read(in_, beast::bind_front_handler(&Viewer::onRead, shared_from_this())); }

  void onRead(beast::error_code ec, std::size_t) {
    if (ec) {
      if (ec == websocket::error::message_too_big) {
        server_.counters.messagesRejected.fetch_add(1, std::memory_order_relaxed);
        server_.counters.viewersDropped.fetch_add(1, std::memory_order_relaxed);
        server_.logLimited(fmt::format("vr: viewer {} ({}) dropped: a message over {} bytes", id_, peer_,
                                       server_.settings.maxMessageBytes));
      } else if (!closing_) {
        server_.logLimited(fmt::format("vr: viewer {} left ({})", id_,
                                       ec == websocket::error::closed ? std::string("closed") : ec.message()));
      }
      closing_ = true;
      return;
    }
    handle();
    in_.consume(in_.size());
    if (!closing_) read();
  }

  void handle() {
    // Token bucket: a sustained rate with a burst on top; over it the message is not even parsed.
    const Clock::time_point now = Clock::now();
    const VrServerSettings& s = server_.settings;
    tokens_ = std::min(s.messageBurst, tokens_ + s.messagesPerSecond * secondsBetween(lastRefill_, now));
    lastRefill_ = now;
    if (tokens_ < 1.0) return strike("over the rate limit", false);
    tokens_ -= 1.0;
    if (!ws_.got_text()) return strike("a binary message (viewers send JSON text)", true);
    const std::string_view text(static_cast<const char*>(in_.data().data()), in_.size());
    vr::ClientMessage m;
    try {
      m = vr::parseClientMessage(text);
    } catch (const Error& e) {
      return strike(e.what(), true);
    }
    server_.counters.messagesReceived.fetch_add(1, std::memory_order_relaxed);
    switch (m.type) {
      case vr::ClientMessage::Type::Input:
        server_.onInput(m.input);
        break;
      case vr::ClientMessage::Type::Ping:
        reply(json{{"type", "pong"}, {"t", m.pingTime}, {"step", server_.latest.step}}.dump());
        break;
      case vr::ClientMessage::Type::Study:
        if (!server_.settings.onStudy) return strike("a study message, but no study is running", true);
        server_.settings.onStudy(m.study);
        break;
      case vr::ClientMessage::Type::Hello:
        if (!greeted_)
          server_.logLimited(fmt::format("vr: viewer {} is {}", id_, m.client.empty() ? "a page" : m.client));
        greeted_ = true;
        break;
    }
  }

  void strike(const std::string& reason, bool answer) {
    server_.counters.messagesRejected.fetch_add(1, std::memory_order_relaxed);
    ++strikes_;
    if (strikes_ <= kLoggedStrikes) {
      server_.logLimited(fmt::format("vr: viewer {} ({}): rejected {}{}", id_, peer_, reason,
                                     strikes_ == kLoggedStrikes ? " (further rejections are only counted)" : ""));
      if (answer) reply(json{{"type", "error"}, {"reason", reason}}.dump());
    }
    if (strikes_ >= server_.settings.maxStrikes) {
      server_.logLimited(fmt::format("vr: viewer {} ({}) dropped after {} rejected messages", id_, peer_, strikes_));
      server_.counters.viewersDropped.fetch_add(1, std::memory_order_relaxed);
      close(websocket::close_code::policy_error, "too many rejected messages");
    }
  }

  void reply(std::string text) {
    if (control_.size() >= kMaxControlMessages) return;  // a viewer not reading its replies gets no more
    control_.push_back({nullptr, std::move(text)});
    pump();
  }

  void write(Outgoing m) {
    ws_.text(!m.binary);
    held_.clear();
    buffers_.clear();
    if (m.binary) {
      held_.push_back(m.binary);
      buffers_.push_back(net::buffer(*m.binary));
    } else {
      text_ = std::move(m.text);
      buffers_.push_back(net::buffer(std::as_const(text_)));
    }
    send(buffers_[0].size());
  }

  // The newest frame: the header and the blocks of the bodies that changed since this viewer's
  // last frame, written straight from the shared blocks.
  void writeFrame() {
    header_ = server_.header;
    held_.clear();
    buffers_.clear();
    buffers_.push_back(net::buffer(header_));
    std::size_t size = header_.size();
    for (std::size_t b = 0; b < server_.bodies.size(); ++b) {
      const auto& body = server_.bodies[b];
      if (!body.block || body.version == sentVersion_[b]) continue;
      sentVersion_[b] = body.version;
      held_.push_back(body.block);
      buffers_.push_back(net::buffer(*body.block));
      size += body.block->size();
    }
    vr::setBlockCount(header_, std::uint32_t(held_.size()));
    if (sentFrame_ > 0 && server_.frameNumber > sentFrame_ + 1)
      server_.counters.framesSkipped.fetch_add(server_.frameNumber - sentFrame_ - 1, std::memory_order_relaxed);
    sentFrame_ = server_.frameNumber;
    server_.counters.framesSent.fetch_add(1, std::memory_order_relaxed);
    ws_.binary(true);
    send(size);
  }

  // Writes buffers_ (one buffer type for every message, so the write is compiled once).
  void send(std::size_t bytes) {
    writing_ = true;
    writeStart_ = Clock::now();
    raiseTo(server_.counters.maxInFlightBytes, bytes);
    ws_.async_write(buffers_, beast::bind_front_handler(&Viewer::onWrite, shared_from_this()));
  }

  void onWrite(beast::error_code ec, std::size_t bytes) {
    writing_ = false;
    held_.clear();
    if (ec) {
      closing_ = true;
      return;
    }
    server_.counters.bytesSent.fetch_add(bytes, std::memory_order_relaxed);
    pump();
  }

  Server& server_;
  websocket::stream<beast::tcp_stream> ws_;
  std::uint64_t id_;
  std::string peer_;
  beast::flat_buffer in_;
  std::deque<Outgoing> control_;
  std::vector<std::uint64_t> sentVersion_;  // per body: the block version this viewer has
  std::uint32_t sentFrame_ = 0;
  std::array<std::uint8_t, vr::frame::kHeaderBytes> header_{};
  std::vector<std::shared_ptr<const Bytes>> held_;  // alive until the write completes
  std::vector<net::const_buffer> buffers_;
  std::string text_;
  bool accepted_ = false, writing_ = false, closing_ = false, greeted_ = false;
  Clock::time_point writeStart_{};
  double tokens_;
  Clock::time_point lastRefill_;
  int strikes_ = 0;
};

// --- HTTP: the page, status.json, and the upgrade to a viewer ---------------------------------------

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(Server& server, tcp::socket&& socket) : server_(server), stream_(std::move(socket)) {}

  void start() { read(); }
  void abort() {
    beast::error_code ec;
    stream_.socket().close(ec);
  }

 private:
  void read() {
    parser_.emplace();
    parser_->header_limit(kMaxRequestHeader);
    stream_.expires_after(kHttpTimeout);
    http::async_read_header(stream_, buffer_, *parser_,
                            beast::bind_front_handler(&HttpSession::onRead, shared_from_this()));
  }

  void onRead(beast::error_code ec, std::size_t) {
    if (ec == http::error::end_of_stream || ec == beast::error::timeout || ec == net::error::operation_aborted ||
        ec == net::error::connection_reset || ec == net::error::bad_descriptor) {
      shutdown();
      return;
    }
    if (ec) {
      const bool tooLarge = ec == http::error::header_limit || ec == http::error::buffer_overflow;
      respondError(tooLarge ? http::status::request_header_fields_too_large : http::status::bad_request,
                   fmt::format("malformed request ({})", ec.message()), 11, false);
      return;
    }
    if (!parser_->is_done()) {  // a body: nothing here takes one, so the connection ends after the answer
      const http::verb method = parser_->get().method();
      const bool read = method == http::verb::get || method == http::verb::head;
      return respondError(read ? http::status::bad_request : http::status::method_not_allowed,
                          read ? "a request body" : fmt::format("method {}", parser_->get().method_string()),
                          parser_->get().version(), false);
    }
    http::request<http::empty_body> req = parser_->release();
    if (websocket::is_upgrade(req)) return upgrade(std::move(req));
    handle(req);
  }

  void upgrade(http::request<http::empty_body> req) {
    const std::string_view target(req.target().data(), req.target().size());
    if (target.substr(0, target.find('?')) != "/ws")
      return respondError(http::status::not_found, "WebSocket upgrade other than /ws", req.version(), false);
    if (server_.counters.viewers.load() >= server_.settings.maxViewers || server_.shuttingDown) {
      server_.counters.viewersRefused.fetch_add(1, std::memory_order_relaxed);
      return respondError(http::status::service_unavailable,
                          fmt::format("{} viewers already connected", server_.settings.maxViewers), req.version(),
                          false);
    }
    const std::string peer = peerOf(stream_);
    auto viewer = std::make_shared<Viewer>(server_, std::move(stream_), server_.nextViewer++, peer);
    server_.viewers.push_back(viewer);
    viewer->start(std::move(req));
  }

  void handle(const http::request<http::empty_body>& req) {
    const std::string_view target(req.target().data(), req.target().size());
    const unsigned version = req.version();
    const bool keepAlive = req.keep_alive();
    if (req.method() != http::verb::get && req.method() != http::verb::head)
      return respondError(http::status::method_not_allowed, fmt::format("method {}", req.method_string()), version,
                          keepAlive);
    const bool head = req.method() == http::verb::head;
    if (target.substr(0, target.find('?')) == "/status.json") {
      http::response<http::string_body> res{http::status::ok, version};
      res.set(http::field::content_type, "application/json");
      res.set(http::field::cache_control, "no-store");
      res.body() = server_.statusJson();
      res.prepare_payload();
      if (head) res.body().clear();
      return send(std::move(res), keepAlive);
    }
    const std::optional<std::filesystem::path> file = resolveStaticPath(server_.web, target);
    if (!file)
      return respondError(http::status::not_found, fmt::format("no file {}", target.substr(0, 200)), version,
                          keepAlive);
    beast::error_code ec;
    http::file_body::value_type body;
    body.open(file->c_str(), beast::file_mode::scan, ec);
    if (ec)
      return respondError(http::status::not_found, fmt::format("cannot read {}", file->string()), version, keepAlive);
    const std::uint64_t size = body.size();
    const std::string type(mimeType(*file));
    const auto common = [&](auto& res) {
      res.set(http::field::server, "vrdeform");
      res.set(http::field::content_type, type);
      res.set(http::field::cache_control, "no-cache");
      res.set("X-Content-Type-Options", "nosniff");
      res.content_length(size);
      res.keep_alive(keepAlive);
    };
    if (head) {  // the headers alone (a string body, left empty: one write fewer to compile)
      http::response<http::string_body> res{http::status::ok, version};
      common(res);
      return send(std::move(res), keepAlive);
    }
    http::response<http::file_body> res{std::piecewise_construct, std::make_tuple(std::move(body)),
                                        std::make_tuple(http::status::ok, version)};
    common(res);
    send(std::move(res), keepAlive);
  }

  void respondError(http::status status, const std::string& reason, unsigned version, bool keepAlive) {
    server_.counters.httpErrors.fetch_add(1, std::memory_order_relaxed);
    server_.logLimited(fmt::format("vr: http {} from {}: {}", unsigned(status), peerOf(stream_), reason));
    http::response<http::string_body> res{status, version};
    res.set(http::field::server, "vrdeform");
    res.set(http::field::content_type, "text/plain; charset=utf-8");
    if (status == http::status::method_not_allowed) res.set(http::field::allow, "GET, HEAD");
    res.body() = std::string(http::obsolete_reason(status)) + "\n";
    res.prepare_payload();
    send(std::move(res), keepAlive);
  }

  template <class Body>
  void send(http::response<Body>&& response, bool keepAlive) {
    server_.counters.httpRequests.fetch_add(1, std::memory_order_relaxed);
    response.keep_alive(keepAlive);
    auto res = std::make_shared<http::response<Body>>(std::move(response));
    stream_.expires_after(kHttpTimeout);
    http::async_write(stream_, *res, [self = shared_from_this(), res, keepAlive](beast::error_code ec, std::size_t) {
      if (ec || !keepAlive) return self->shutdown();
      self->read();
    });
  }

  void shutdown() {
    beast::error_code ec;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
  }

  Server& server_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::empty_body>> parser_;
};

// --- The server ----------------------------------------------------------------------------------------

// The world as it is before the loop's first step: the first frame of a scene shown.
Snapshot firstSnapshot(const BuiltScene& scene) {
  Snapshot s;
  captureSnapshot(s, *scene.world, nullptr, 0, 0.0);
  return s;
}

Server::Server(SimulationLoop& loop_, const BuiltScene& scene_, std::filesystem::path web_, VrServerSettings settings_,
               LiveHandInput* hand_)
    : web(std::move(web_)), settings(std::move(settings_)) {
  if (!(settings.frameRate >= 1.0 && settings.frameRate <= 1000.0))
    throw Error(fmt::format("vr server: frame rate {} is outside [1, 1000]", settings.frameRate));
  if (settings.maxMessageBytes < 1024) throw Error("vr server: maxMessageBytes must be at least 1024");
  present(loop_, scene_, hand_, firstSnapshot(scene_));
}

void Server::present(SimulationLoop& loop_, const BuiltScene& scene_, LiveHandInput* hand_, const Snapshot& first) {
  std::vector<ViewMesh> shown = viewMeshes(scene_);
  auto message = std::make_shared<const std::string>(vr::sceneMessage(scene_, shown, settings.frameRate));
  auto topo = std::make_shared<const Bytes>(vr::encodeTopology(shown));
  loop = &loop_;
  scene = &scene_;
  hand = hand_;
  driven = false;
  radius = scene->session.hand.geometry.fingertipRadius;
  meshes = std::move(shown);
  bodies.assign(meshes.size(), {});
  for (std::size_t b = 0; b < meshes.size(); ++b) bodies[b].positions.resize(meshes[b].vertexCount());
  sceneJson = std::move(message);
  topology = std::move(topo);
  channel = loop->subscribe();
  takeSnapshot(first);
}

void Server::log(std::string_view line) const {
  if (settings.log)
    settings.log(line);
  else
    fmt::print(stderr, "{}\n", line);
}

void Server::logLimited(std::string_view line) {
  if (!limiter.allow()) return;
  const std::uint64_t held = limiter.takeSuppressed();
  if (held > 0) log(fmt::format("vr: ({} log lines held back)", held));
  log(line);
}

void Server::run() {
  for (;;) {
    try {
      ioc->run();
      break;
    } catch (const std::exception& e) {  // a handler failed: say so and carry on serving
      log(fmt::format("vr: error on the server thread: {}", e.what()));
    }
  }
  ioDone.store(true);
}

void Server::tick() {
  if (shuttingDown) return;
  const Clock::time_point now = Clock::now();
  if (channel->update()) takeSnapshot(channel->front());
  if (hand && driven && secondsBetween(lastInput, now) > settings.hand.timeout) {
    hand->set(xrParkedFrame(settings.hand, radius));  // the viewer went quiet: let go, wait parked
    driven = false;
  }
  std::uint64_t behind = 0;
  for (auto it = viewers.begin(); it != viewers.end();) {
    if (const std::shared_ptr<Viewer> v = it->lock()) {
      v->checkStalled(now);
      v->pump();
      behind += v->behind() ? 1 : 0;
      ++it;
    } else {
      it = viewers.erase(it);
    }
  }
  counters.viewersBehind.store(behind, std::memory_order_relaxed);
  std::erase_if(httpSessions, [](const std::weak_ptr<HttpSession>& s) { return s.expired(); });
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / settings.frameRate));
  nextTick += period;
  if (nextTick < now) nextTick = now + period;  // behind: no burst of catch-up ticks
  timer->expires_at(nextTick);
  timer->async_wait([this](beast::error_code ec) {
    if (!ec) tick();
  });
}

void Server::takeSnapshot(const Snapshot& s) {
  counters.snapshots.fetch_add(1, std::memory_order_relaxed);
  for (std::size_t b = 0; b < meshes.size(); ++b) {
    BodyFrame& body = bodies[b];
    updateViewMesh(meshes[b], bodyPositions(s, meshes[b].body), body.positions, {});
    Bytes block = vr::encodeBodyBlock(std::uint32_t(b), body.positions, body.box);
    if (!body.block || *body.block != block) {
      body.block = std::make_shared<const Bytes>(std::move(block));
      ++body.version;
    }
  }
  std::uint32_t flags = 0;
  if (driven) flags |= vr::kDriven;
  if (settings.gloveConnected && settings.gloveConnected()) flags |= vr::kGlove;
  header = vr::encodeFrameHeader(s, ++frameNumber, flags);
  latest.step = s.step;
  latest.time = s.time;
  latest.haptics = s.haptics;
  latest.fingerPresent = s.fingerPresent;
  latest.fingertips = s.fingertips;
  latest.grasping = s.grasping;
  latest.contact = s.contact;
}

void Server::onInput(const XrInput& input) {
  if (input.head) head = input.head;
  if (!hand || input.source == XrSource::None) return;
  std::optional<float> closure;
  if (settings.gloveClosure) closure = settings.gloveClosure();
  hand->set(xrHandFrame(input, settings.hand, radius, closure));
  lastInput = Clock::now();
  driven = true;
  counters.inputs.fetch_add(1, std::memory_order_relaxed);
}

std::string Server::statusJson() const {
  json force = json::array(), newtons = json::array(), tips = json::array();
  for (int f = 0; f < kFingerCount; ++f) {
    const bool present = latest.fingerPresent[f];
    force.push_back(present ? clampUnit(latest.haptics.fingers[f].force) : 0.0f);
    newtons.push_back(present ? latest.haptics.fingers[f].newtons : 0.0f);
    tips.push_back(present ? json{latest.fingertips[f].x(), latest.fingertips[f].y(), latest.fingertips[f].z()}
                           : json(nullptr));
  }
  const auto c = [](const std::atomic<std::uint64_t>& a) { return a.load(std::memory_order_relaxed); };
  json j = {{"scene", scene->spec.name},
            {"step", latest.step},
            {"time", latest.time},
            {"frame", frameNumber},
            {"driven", driven},
            {"grasping", latest.grasping},
            {"contact", latest.contact},
            {"force", force},
            {"newtons", newtons},
            {"paper", clampUnit(latest.haptics.paper)},
            {"fingertips", tips},
            {"glove", settings.gloveConnected && settings.gloveConnected()},
            {"viewers", c(counters.viewers)},
            {"stats",
             {{"viewersTotal", c(counters.viewersTotal)},
              {"viewersRefused", c(counters.viewersRefused)},
              {"viewersDropped", c(counters.viewersDropped)},
              {"framesSent", c(counters.framesSent)},
              {"framesSkipped", c(counters.framesSkipped)},
              {"bytesSent", c(counters.bytesSent)},
              {"maxInFlightBytes", c(counters.maxInFlightBytes)},
              {"messagesReceived", c(counters.messagesReceived)},
              {"messagesRejected", c(counters.messagesRejected)},
              {"inputs", c(counters.inputs)},
              {"httpRequests", c(counters.httpRequests)},
              {"httpErrors", c(counters.httpErrors)},
              {"snapshots", c(counters.snapshots)},
              {"viewersBehind", c(counters.viewersBehind)}}}};
  if (head) j["head"] = {head->position.x(), head->position.y(), head->position.z()};
  return j.dump();
}

void Server::shutdown() {
  shuttingDown = true;
  beast::error_code ec;
  acceptor->close(ec);
  if (tls) tls->stop();
  timer->cancel();
  for (const std::weak_ptr<Viewer>& w : viewers)
    if (const auto v = w.lock()) v->close(websocket::close_code::going_away, "the server is stopping");
  for (const std::weak_ptr<HttpSession>& w : httpSessions)
    if (const auto s = w.lock()) s->abort();
}

void acceptNext(Server& server) {
  server.acceptor->async_accept([&server](beast::error_code ec, tcp::socket socket) {
    if (server.shuttingDown) return;
    if (!ec) {
      auto session = std::make_shared<HttpSession>(server, std::move(socket));
      server.httpSessions.push_back(session);
      session->start();
    } else if (ec != net::error::operation_aborted) {
      server.logLimited(fmt::format("vr: accept failed: {}", ec.message()));
    }
    if (server.acceptor->is_open()) acceptNext(server);
  });
}

}  // namespace

struct VrServer::Impl : Server {
  using Server::Server;
};

VrServer::VrServer(SimulationLoop& loop, const BuiltScene& scene, std::filesystem::path web, VrServerSettings settings,
                   LiveHandInput* hand)
    : impl_(std::make_unique<Impl>(loop, scene, std::move(web), std::move(settings), hand)) {}

VrServer::~VrServer() { stop(); }

void VrServer::start() {
  Impl& s = *impl_;
  if (s.ioc) throw Error("vr server: start() twice");
  s.ioc.emplace(1);
  beast::error_code ec;
  const net::ip::address address = net::ip::make_address(s.settings.bind, ec);
  if (ec) throw Error(fmt::format("--bind {}: not an IP address", s.settings.bind));
  s.acceptor.emplace(*s.ioc);
  // With TLS the plain server listens on a loopback port of its own, behind the TLS front.
  const tcp::endpoint endpoint =
      s.settings.tls ? tcp::endpoint(net::ip::address_v4::loopback(), 0) : tcp::endpoint(address, s.settings.port);
  s.acceptor->open(endpoint.protocol(), ec);
  if (!ec) s.acceptor->set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) s.acceptor->bind(endpoint, ec);
  if (!ec) s.acceptor->listen(net::socket_base::max_listen_connections, ec);
  if (ec) throw Error(fmt::format("cannot listen on {}:{}: {}", s.settings.bind, s.settings.port, ec.message()));
  s.port.store(s.acceptor->local_endpoint().port());
  if (s.settings.tls) {
    s.tls.emplace(*s.ioc, *s.settings.tls, [&s](std::string_view line) { s.logLimited(std::string(line)); });
    s.tls->start(tcp::endpoint(address, s.settings.port), s.acceptor->local_endpoint());
    s.port.store(s.tls->port());
  }
  s.timer.emplace(*s.ioc);
  s.nextTick = Clock::now();
  acceptNext(s);
  net::post(*s.ioc, [&s] { s.tick(); });
  s.thread = std::thread([&s] { s.run(); });
}

void VrServer::stop() {
  Impl& s = *impl_;
  if (!s.thread.joinable()) return;
  net::post(*s.ioc, [&s] { s.shutdown(); });
  // Give the viewers a moment to receive the close, then stop whatever is left.
  const Clock::time_point until = Clock::now() + std::chrono::seconds(1);
  while (!s.ioDone.load() && Clock::now() < until) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  s.ioc->stop();
  s.thread.join();
  s.timer.reset();
  s.tls.reset();
  s.acceptor.reset();
  s.ioc.reset();  // destroys the handlers still pending, and with them the sessions
  s.viewers.clear();
  s.httpSessions.clear();
}

void VrServer::show(SimulationLoop& loop, const BuiltScene& scene, LiveHandInput* hand, const Vec3& park) {
  Impl& s = *impl_;
  const Snapshot first = firstSnapshot(scene);
  if (!s.thread.joinable() || s.ioDone.load()) {
    s.settings.hand.park = park;
    return s.present(loop, scene, hand, first);
  }
  std::promise<void> done;
  net::post(*s.ioc, [&] {
    try {
      s.settings.hand.park = park;
      s.present(loop, scene, hand, first);
      for (const std::weak_ptr<Viewer>& w : s.viewers)
        if (const auto v = w.lock()) v->reshow();
      done.set_value();
    } catch (...) {
      done.set_exception(std::current_exception());
    }
  });
  done.get_future().get();
}

void VrServer::setPanel(std::string json) {
  Impl& s = *impl_;
  auto panel = json.empty() ? nullptr : std::make_shared<const std::string>(std::move(json));
  if (!s.thread.joinable() || s.ioDone.load()) {
    s.panel = std::move(panel);
    return;
  }
  net::post(*s.ioc, [&s, panel = std::move(panel)] {
    s.panel = panel;
    for (const std::weak_ptr<Viewer>& w : s.viewers)
      if (const auto v = w.lock()) v->showPanel();
  });
}

std::uint16_t VrServer::port() const { return impl_->port.load(); }

VrServerStats VrServer::stats() const {
  const Counters& c = impl_->counters;
  const auto v = [](const std::atomic<std::uint64_t>& a) { return a.load(std::memory_order_relaxed); };
  return {v(c.viewers),   v(c.viewersTotal),     v(c.viewersRefused),   v(c.framesSent),       v(c.framesSkipped),
          v(c.bytesSent), v(c.maxInFlightBytes), v(c.messagesReceived), v(c.messagesRejected), v(c.viewersDropped),
          v(c.inputs),    v(c.httpRequests),     v(c.httpErrors),       v(c.snapshots),        v(c.viewersBehind)};
}

}  // namespace vrd
