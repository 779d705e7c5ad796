// The VR server over loopback (web/vr_server.h), with a plain WebSocket and HTTP client (Beast):
// the scene and topology then frames, viewers' input driving the hand, hostile input rejected
// without stalling the simulation, and a slow viewer skipping frames in bounded memory; and over
// TLS with its self-signed certificate (web/tls_identity.h), checked by the client.

#include <fmt/format.h>
#include <gtest/gtest.h>

// GCC 12 with the sanitizers sees a false "may be used uninitialized" in Beast's HTTP response
// parser (a boost::optional it fills before reading).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ssl.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/ssl.hpp>
#include <boost/beast/websocket.hpp>
#include <boost/beast/websocket/ssl.hpp>
#pragma GCC diagnostic pop
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "test_support.h"
#include "vrdeform/scene/scene_library.h"
#include "vrdeform/web/static_files.h"
#include "vrdeform/web/tls_identity.h"
#include "vrdeform/web/vr_protocol.h"
#include "vrdeform/web/vr_server.h"

namespace vrd {
namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using json = nlohmann::json;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

// The liver, unsettled and uncalibrated, one substep of two iterations, started cold: the server's
// behaviour does not depend on the physics, and the tests stay quick under the sanitizers. Without
// gravity it lies perfectly still (warm-started, its multipliers carry float rounding from substep
// to substep, and it trembles by an ulp).
BuiltScene liver(bool gravity = true, const std::string& name = "liver") {
  SceneSpec spec = loadSceneByName(name);
  spec.solver.timeStep = float(1.0 / 120.0);
  spec.settle = 0.0;
  spec.haptics.calibrate = false;
  spec.solver.substeps = 1;
  spec.solver.iterations = 2;
  spec.solver.warmStart = false;
  if (!gravity) spec.solver.gravity = Vec3::Zero();
  return buildScene(spec);
}

// A scene, its loop (real time, 120 Hz) and a server on a free loopback port; log lines kept.
struct Served {
  explicit Served(VrServerSettings settings = {}, bool gravity = true) : scene(liver(gravity)) {
    settings.port = 0;
    settings.hand.park = scene.bodies.front().top + Vec3(0.0f, 0.15f, 0.0f);
    settings.log = [this](std::string_view line) {
      std::lock_guard lock(logMutex);
      log += std::string(line) + "\n";
    };
    hand.emplace(xrParkedFrame(settings.hand, scene.session.hand.geometry.fingertipRadius));
    SimulationLoopSettings ls;
    ls.input = &*hand;
    loop.emplace(scene, ls);
    server.emplace(*loop, scene, webFolder(), settings, &*hand);
    server->start();
    loop->start();
  }
  ~Served() {
    server->stop();
    loop->stop();
  }
  std::string logText() {
    std::lock_guard lock(logMutex);
    return log;
  }

  BuiltScene scene;
  std::optional<LiveHandInput> hand;
  std::optional<SimulationLoop> loop;
  std::optional<VrServer> server;
  std::mutex logMutex;
  std::string log;
};

template <class T>
T read(const std::string& s, std::size_t at) {
  T v;
  std::memcpy(&v, s.data() + at, sizeof v);
  return v;
}

struct Client {
  net::io_context ioc;
  websocket::stream<tcp::socket> ws{ioc};

  explicit Client(std::uint16_t port, int receiveBuffer = 0) {
    ws.next_layer().open(tcp::v4());
    if (receiveBuffer > 0) ws.next_layer().set_option(net::socket_base::receive_buffer_size(receiveBuffer));
    ws.next_layer().connect({net::ip::make_address("127.0.0.1"), port});
    ws.read_message_max(64 << 20);
    ws.handshake("127.0.0.1", "/ws");
  }
  // The next message; `text` tells which kind it was.
  std::string next(bool* text = nullptr) {
    beast::flat_buffer b;
    ws.read(b);
    if (text) *text = ws.got_text();
    return beast::buffers_to_string(b.data());
  }
  void send(const std::string& s, bool binary = false) {
    ws.binary(binary);
    ws.write(net::buffer(s));
  }
  // The next text message (frames skipped on the way).
  json nextJson() {
    for (;;) {
      bool text = false;
      const std::string m = next(&text);
      if (text) return json::parse(m);
    }
  }
  // Reads until the server closes; returns the close code (or 0 if none came before an error).
  int closeCode() {
    try {
      for (;;) next();
    } catch (const beast::system_error& e) {
      if (e.code() == websocket::error::closed) return int(ws.reason().code);
    }
    return 0;
  }
};

// One plain HTTP exchange, written as raw bytes.
std::string rawHttp(std::uint16_t port, const std::string& request) {
  net::io_context ioc;
  tcp::socket s(ioc);
  s.connect({net::ip::make_address("127.0.0.1"), port});
  net::write(s, net::buffer(request));
  std::string out;
  beast::error_code ec;
  for (;;) {
    char buf[4096];
    const std::size_t n = s.read_some(net::buffer(buf), ec);
    out.append(buf, n);
    if (ec) break;
  }
  return out;
}

std::string get(std::uint16_t port, const std::string& target) {
  return rawHttp(port, "GET " + target + " HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
}

json status(std::uint16_t port) {
  const std::string r = get(port, "/status.json");
  return json::parse(r.substr(r.find("\r\n\r\n") + 4));
}

bool eventually(const std::function<bool()>& f, std::chrono::milliseconds within = 5000ms) {
  const auto end = Clock::now() + within;
  while (Clock::now() < end) {
    if (f()) return true;
    std::this_thread::sleep_for(10ms);
  }
  return f();
}

TEST(VrServer, ServesThePageAndStatusAndRefusesBadRequests) {
  Served s;
  const std::uint16_t port = s.server->port();
  const std::string page = get(port, "/");
  EXPECT_EQ(page.rfind("HTTP/1.1 200", 0), 0u) << page.substr(0, 200);
  EXPECT_NE(page.find("Content-Type: text/html"), std::string::npos);
  EXPECT_NE(page.find("importmap"), std::string::npos);
  if (hasThreeJs(webFolder())) {
    const std::string three =
        rawHttp(port, "HEAD /three/build/three.module.js HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n");
    EXPECT_EQ(three.rfind("HTTP/1.1 200", 0), 0u);
    EXPECT_NE(three.find("text/javascript"), std::string::npos);
    // The file's length, and nothing after the headers.
    const std::string whole = get(port, "/three/build/three.module.js");
    const std::size_t bodyAt = whole.find("\r\n\r\n") + 4;
    EXPECT_NE(three.find(fmt::format("Content-Length: {}\r\n", whole.size() - bodyAt)), std::string::npos);
    EXPECT_EQ(three.find("\r\n\r\n") + 4, three.size());
  }
  EXPECT_EQ(status(port)["scene"], "liver");
  const auto code = [](const std::string& r) { return r.substr(0, 12); };
  EXPECT_EQ(code(get(port, "/../CMakeLists.txt")), "HTTP/1.1 404");
  EXPECT_EQ(code(get(port, "/%2e%2e/package.json")), "HTTP/1.1 404");
  EXPECT_EQ(code(rawHttp(port, "POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 3\r\n\r\nabc")), "HTTP/1.1 405");
  EXPECT_EQ(code(rawHttp(port, "GET / HTTP/1.1\r\nHost: x\r\nX: " + std::string(20000, 'a') + "\r\n\r\n")),
            "HTTP/1.1 431");
  EXPECT_EQ(code(rawHttp(port, "\x16\x03\x01\x02\x00garbage\r\n\r\n")), "HTTP/1.1 400");
  EXPECT_EQ(code(rawHttp(port, "GET /x.html HTTP/1.1\r\nHost: x\r\nContent-Length: 2\r\n\r\nab")), "HTTP/1.1 400");
  EXPECT_EQ(code(rawHttp(port,
                         "GET /other HTTP/1.1\r\nHost: x\r\nConnection: Upgrade\r\nUpgrade: websocket\r\n"
                         "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n")),
            "HTTP/1.1 404");
  EXPECT_GE(s.server->stats().httpErrors, 6u);
  EXPECT_NE(s.logText().find("no file /../CMakeLists.txt"), std::string::npos) << s.logText();
}

TEST(VrServer, ViewersGetTheSceneTopologyThenFramesOfChangedBodiesOnly) {
  Served s({}, /*gravity=*/false);
  const std::vector<ViewMesh> meshes = viewMeshes(s.scene);
  Client a(s.server->port());
  bool text = false;
  const json scene = json::parse(a.next(&text));
  EXPECT_TRUE(text);
  EXPECT_EQ(scene["type"], "scene");
  EXPECT_EQ(scene["bodies"][0]["vertices"], meshes[0].vertexCount());
  const std::string topology = a.next(&text);
  ASSERT_FALSE(text);
  EXPECT_EQ(read<std::uint32_t>(topology, 0), vr::kMagic);
  EXPECT_EQ(read<std::uint16_t>(topology, 4), std::uint16_t(vr::MessageKind::Topology));
  EXPECT_EQ(read<std::uint32_t>(topology, 8), 1u);
  EXPECT_EQ(read<std::uint32_t>(topology, 12), meshes[0].vertexCount());
  EXPECT_EQ(read<std::uint32_t>(topology, 16), meshes[0].triangles.size());
  EXPECT_EQ(topology.size(), 12 + 16 + 12 * meshes[0].triangles.size());
  EXPECT_EQ(read<std::uint32_t>(topology, 28 + 4), std::uint32_t(meshes[0].triangles[0][1]));

  // The first frame holds the body; a body lying still is left out of the frames after it.
  const std::string first = a.next();
  EXPECT_EQ(read<std::uint16_t>(first, 4), std::uint16_t(vr::MessageKind::Frame));
  ASSERT_EQ(read<std::uint32_t>(first, vr::frame::kBlocks), 1u);
  EXPECT_EQ(read<std::uint32_t>(first, vr::frame::kHeaderBytes + 4), meshes[0].vertexCount());
  EXPECT_EQ(first.size(),
            vr::frame::kHeaderBytes + vr::frame::kBlockHeaderBytes + (6 * meshes[0].vertexCount() + 3) / 4 * 4);
  std::uint32_t number = read<std::uint32_t>(first, vr::frame::kNumber);
  std::uint64_t step = read<std::uint64_t>(first, vr::frame::kStep);
  for (int k = 0; k < 5; ++k) {
    const std::string f = a.next();
    EXPECT_EQ(f.size(), vr::frame::kHeaderBytes);
    EXPECT_EQ(read<std::uint32_t>(f, vr::frame::kBlocks), 0u);
    EXPECT_GT(read<std::uint32_t>(f, vr::frame::kNumber), number);
    EXPECT_GT(read<std::uint64_t>(f, vr::frame::kStep), step);
    number = read<std::uint32_t>(f, vr::frame::kNumber);
    step = read<std::uint64_t>(f, vr::frame::kStep);
  }
  // A second viewer gets the body in its first frame: what is left out is per viewer.
  Client b(s.server->port());
  b.next(), b.next();
  EXPECT_EQ(read<std::uint32_t>(b.next(), vr::frame::kBlocks), 1u);
  EXPECT_EQ(s.server->stats().viewers, 2u);
  b.send(R"({"type":"ping","t":7})");
  const json pong = b.nextJson();
  EXPECT_EQ(pong["type"], "pong");
  EXPECT_EQ(pong["t"], 7);
  // No study runs here: a study reply is refused with the reason.
  b.send(R"({"type":"study","panel":1,"action":"start"})");
  EXPECT_EQ(b.nextJson()["reason"], "a study message, but no study is running");
}

// `study run --vr`: the server shows one scene after another and a study's panel; every viewer
// gets the new scene, its topology and the panel, and the participants' replies are passed on.
TEST(VrServer, ShowsAnotherSceneAndAStudyPanelAndPassesOnTheReplies) {
  std::mutex repliesMutex;
  std::vector<vr::StudyReply> replies;
  VrServerSettings settings;
  settings.onStudy = [&](const vr::StudyReply& r) {
    std::lock_guard lock(repliesMutex);
    replies.push_back(r);
  };
  Served s(settings, /*gravity=*/false);
  Client a(s.server->port());
  EXPECT_EQ(a.nextJson()["name"], "liver");
  s.server->setPanel(R"({"type":"study","id":1,"step":"trial"})");
  EXPECT_EQ(a.nextJson()["id"], 1);
  a.send(R"({"type":"study","panel":1,"action":"submit","ratings":[4,-2],"texts":["ok"]})");
  ASSERT_TRUE(eventually([&] {
    std::lock_guard lock(repliesMutex);
    return !replies.empty();
  }));
  {
    std::lock_guard lock(repliesMutex);
    EXPECT_EQ(replies[0].panel, 1u);
    EXPECT_EQ(replies[0].action, vr::StudyReply::Action::Submit);
    EXPECT_EQ(replies[0].ratings, (std::vector<int>{4, -2}));
    EXPECT_EQ(replies[0].texts, (std::vector<std::string>{"ok"}));
  }

  // Another scene, its loop not started: its first frame is the world as built.
  BuiltScene flag = liver(false, "flag");
  LiveHandInput hand;
  SimulationLoopSettings ls;
  ls.input = &hand;
  SimulationLoop loop(flag, ls);
  const Vec3 park = flag.bodies.front().top + Vec3(0.0f, 0.2f, 0.0f);
  s.server->show(loop, flag, &hand, park);
  s.loop->stop();  // the liver's loop may go now
  const std::vector<ViewMesh> meshes = viewMeshes(flag);
  json m;
  do m = a.nextJson();
  while (m["type"] != "scene");
  EXPECT_EQ(m["name"], "flag");
  bool text = true;
  const std::string topology = a.next(&text);
  ASSERT_FALSE(text);
  EXPECT_EQ(read<std::uint32_t>(topology, 12), meshes[0].vertexCount());
  EXPECT_EQ(a.nextJson()["id"], 1);  // the panel again, after the scene
  const std::string first = a.next(&text);
  ASSERT_FALSE(text);
  ASSERT_EQ(read<std::uint32_t>(first, vr::frame::kBlocks), 1u);
  EXPECT_EQ(read<std::uint32_t>(first, vr::frame::kHeaderBytes + 4), meshes[0].vertexCount());
  EXPECT_EQ(read<std::uint64_t>(first, vr::frame::kStep), 0u);
  // A viewer that comes later gets the flag and the panel.
  Client b(s.server->port());
  EXPECT_EQ(b.nextJson()["name"], "flag");
  b.next();
  EXPECT_EQ(b.nextJson()["step"], "trial");
  EXPECT_EQ(status(s.server->port())["scene"], "flag");
  a.ws.next_layer().close();  // gone: the server stops without waiting for their close handshakes
  b.ws.next_layer().close();
  s.server->stop();  // before the flag and its loop go
}

TEST(VrServer, AViewersControllerDrivesTheHandUntilItGoesQuiet) {
  VrServerSettings settings;
  settings.hand.timeout = 0.3;
  Served s(settings);
  Client a(s.server->port());
  a.next(), a.next();
  const Vec3 top = s.scene.bodies.front().top;
  const Vec3 ray = top + Vec3(0.0f, 0.1f, 0.0f);  // 10 cm above the top, pointing down: clear of it
  const std::string input = fmt::format(
      R"({{"type":"input","hand":{{"source":"controller","ray":{{"p":[{},{},{}],"q":[-0.5,-0.5,-0.5,0.5]}},"trigger":0}}}})",
      ray.x(), ray.y(), ray.z());
  const float r = s.scene.session.hand.geometry.fingertipRadius;
  const Vec3 index = ray - Vec3(0.0f, settings.hand.reach, 0.0f) + Vec3(0.5f * settings.hand.openGap + r, 0.0f, 0.0f);
  // The frames' fingertips follow the input (the hand is a kinematic goal: allow a millimetre).
  bool driven = false;
  for (int k = 0; k < 200 && !driven; ++k) {
    a.send(input);
    const std::string f = a.next();
    const std::uint32_t flags = read<std::uint32_t>(f, vr::frame::kFlags);
    Vec3 tip;
    for (int c = 0; c < 3; ++c) tip[c] = read<float>(f, vr::frame::kFingertips + 12 * 1 + 4 * c);
    driven = (flags & vr::kDriven) && (tip - index).norm() < 1e-3f;
  }
  EXPECT_TRUE(driven);
  EXPECT_GT(s.server->stats().inputs, 0u);
  // Silent for longer than the timeout: the hand goes back to its park and the flag clears.
  EXPECT_TRUE(eventually([&] { return !status(s.server->port())["driven"].get<bool>(); }));
  const float park = top.y() + 0.15f;  // Served parks the hand 15 cm over the top
  EXPECT_TRUE(eventually([&] {
    return std::abs(status(s.server->port())["fingertips"][1][1].get<float>() - park) < 1e-3f;
  })) << status(s.server->port()).dump();
}

TEST(VrServer, HostileInputIsRejectedAndTheLoopKeepsStepping) {
  VrServerSettings settings;
  settings.maxViewers = 3;
  Served s(settings);
  const std::uint16_t port = s.server->port();
  const auto steps = [&] { return s.loop->steps(); };

  // Malformed, wrong types, a binary message: each refused with a reason, the viewer stays.
  Client a(port);
  a.next(), a.next();
  a.send("{");
  EXPECT_EQ(a.nextJson()["reason"], "malformed JSON");
  a.send(R"({"type":"launch"})");
  EXPECT_EQ(a.nextJson()["reason"], "unknown message type 'launch'");
  a.send("\x01\x02\x03", true);
  EXPECT_EQ(a.nextJson()["reason"], "a binary message (viewers send JSON text)");
  a.send(R"({"type":"input","hand":{"source":"controller","ray":{"p":[0,0,1e30],"q":[0,0,0,1]}}})");
  a.send(R"({"type":"ping","t":1})");
  EXPECT_EQ(a.nextJson()["type"], "pong");  // still served; later rejections are counted, not answered
  EXPECT_EQ(s.server->stats().messagesRejected, 4u);

  // Oversized: the connection is closed with "message too big".
  Client b(port);
  b.next(), b.next();
  try {
    b.send(std::string(100 * 1024, ' '));
  } catch (const beast::system_error&) {  // closed under us before the whole message went out (a broken pipe)
  }
  const int tooBig = b.closeCode();  // the close frame, or a reset when the server closes with unread data
  EXPECT_TRUE(tooBig == int(websocket::close_code::too_big) || tooBig == 0) << tooBig;

  // A flood far over the rate: disconnected for abuse (policy).
  Client c(port);
  c.next(), c.next();
  int sent = 0;
  try {
    for (; sent < 5000; ++sent) c.send(R"({"type":"hello"})");
  } catch (const beast::system_error&) {  // closed under us
  }
  const int code = c.closeCode();
  EXPECT_TRUE(code == int(websocket::close_code::policy_error) || code == 0) << code;
  EXPECT_TRUE(eventually([&] { return s.server->stats().viewersDropped >= 2; })) << s.logText();

  // More viewers than allowed: refused with 503, the others carry on.
  EXPECT_TRUE(eventually([&] { return s.server->stats().viewers == 1; }));
  Client d(port), e(port);
  (void)d;
  EXPECT_THROW(Client f(port), beast::system_error);
  EXPECT_GE(s.server->stats().viewersRefused, 1u);

  // The simulation never waited: it still steps, and the first viewer still gets frames.
  const std::uint64_t before = steps();
  EXPECT_TRUE(eventually([&] { return steps() > before + 10; }));
  bool text = true;
  a.next(&text);
  EXPECT_TRUE(eventually([&] { return steps() > before + 20; }));
  const std::string log = s.logText();
  EXPECT_NE(log.find("rejected malformed JSON"), std::string::npos) << log;
  EXPECT_NE(log.find("a message over 65536 bytes"), std::string::npos) << log;
  EXPECT_NE(log.find("dropped after 20 rejected messages"), std::string::npos) << log;
}

TEST(VrServer, ASlowViewerSkipsFramesInBoundedMemoryWhileOthersKeepUp) {
  Served s;  // falling: every frame carries the body
  const std::uint16_t port = s.server->port();
  Client slow(port, 4096);
  slow.next();
  const std::string topology = slow.next();
  const std::string frame = slow.next();
  Client fast(port);
  fast.next(), fast.next();
  // The slow viewer stops reading until the kernel's buffers are full and the server skips frames
  // for it (and a little longer); the fast one keeps reading at display rate meanwhile.
  const auto start = Clock::now();
  std::optional<Clock::time_point> behindSince;
  int fastFrames = 0;
  while (Clock::now() < start + 20s && !(behindSince && Clock::now() > *behindSince + 300ms)) {
    fast.next();
    ++fastFrames;
    if (!behindSince && s.server->stats().viewersBehind > 0) behindSince = Clock::now();
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  ASSERT_TRUE(behindSince) << "the slow viewer never fell behind";
  EXPECT_GT(fastFrames, 20.0 * seconds);  // 72 frames/s at most; a loaded CI machine gets fewer
  testing::record("seconds_to_fall_behind", std::chrono::duration<double>(*behindSince - start).count());
  // At most one message per viewer in flight, whatever the slow one does.
  EXPECT_LE(s.server->stats().maxInFlightBytes, std::max(frame.size(), topology.size()));
  // Reading again it first drains what the kernels buffered (a small backlog), then the frame
  // numbers jump over the ones it never got.
  std::uint32_t last = read<std::uint32_t>(frame, vr::frame::kNumber);
  int firstJump = -1;
  for (int k = 0; k < 300 && firstJump < 0; ++k) {
    const std::uint32_t n = read<std::uint32_t>(slow.next(), vr::frame::kNumber);
    EXPECT_GT(n, last);
    if (n > last + 1) firstJump = k;
    last = n;
  }
  EXPECT_GE(firstJump, 0);
  // The backlog: what the client's receive buffer holds and the 16 kB the server lets the kernel keep.
  EXPECT_LE(std::size_t(firstJump) * frame.size(), 48u * 1024u);
  testing::record("backlog_frames", firstJump);
  EXPECT_GT(s.server->stats().framesSkipped, 0u);
  testing::record("frame_bytes", double(frame.size()));
  testing::record("topology_bytes", double(topology.size()));
  testing::record("frames_skipped", double(s.server->stats().framesSkipped));
}

// --- TLS -----------------------------------------------------------------------------------------

namespace ssl = net::ssl;

// A client context that trusts only `identity`'s certificate and checks that it names 127.0.0.1.
ssl::context trusting(const TlsIdentity& identity) {
  ssl::context c(ssl::context::tls_client);
  c.add_certificate_authority(net::buffer(identity.certificatePem));
  c.set_verify_mode(ssl::verify_peer);
  return c;
}

TEST(TlsIdentity, MadeOnceKeptPrivateAndReadBack) {
  const testing::TempDir dir;
  const TlsIdentity made = loadOrCreateTlsIdentity(dir / "tls", {"192.0.2.7"});
  EXPECT_TRUE(made.created);
  EXPECT_EQ(made.fingerprint.size(), 32u * 3 - 1);  // SHA-256 as AB:CD:...
  EXPECT_EQ(made.spkiHash.size(), 44u);             // base64 of 32 bytes
  namespace fs = std::filesystem;
  EXPECT_EQ(fs::status(dir / "tls" / "key.pem").permissions() & (fs::perms::group_all | fs::perms::others_all),
            fs::perms::none);
  const TlsIdentity read = loadOrCreateTlsIdentity(dir / "tls", {});
  EXPECT_FALSE(read.created);
  EXPECT_EQ(read.fingerprint, made.fingerprint);
  EXPECT_EQ(read.spkiHash, made.spkiHash);
  EXPECT_EQ(read.certificatePem, made.certificatePem);

  // A folder with half a pair, a pair that does not match, garbage: clear errors, nothing made.
  const TlsIdentity other = loadOrCreateTlsIdentity(dir / "other", {});
  EXPECT_NE(other.fingerprint, made.fingerprint);
  fs::create_directories(dir / "half");
  fs::copy_file(dir / "tls" / "cert.pem", dir / "half" / "cert.pem");
  EXPECT_NE(testing::errorOf([&] { loadOrCreateTlsIdentity(dir / "half", {}); }).find("has cert.pem but not key.pem"),
            std::string::npos);
  fs::copy_file(dir / "other" / "key.pem", dir / "half" / "key.pem");
  EXPECT_NE(testing::errorOf([&] { loadOrCreateTlsIdentity(dir / "half", {}); }).find("do not belong together"),
            std::string::npos);
  std::ofstream(dir / "half" / "cert.pem") << "garbage";
  EXPECT_NE(testing::errorOf([&] { loadOrCreateTlsIdentity(dir / "half", {}); }).find("not a PEM certificate"),
            std::string::npos);
}

TEST(VrServer, TlsServesThePageAndTheWebSocketWithItsCertificate) {
  const testing::TempDir dir;
  VrServerSettings settings;
  settings.tls = loadOrCreateTlsIdentity(dir / "tls", {});
  Served s(settings);
  const tcp::endpoint at(net::ip::make_address("127.0.0.1"), s.server->port());
  net::io_context ioc;
  ssl::context context = trusting(*settings.tls);

  // HTTPS: the page, over a connection whose certificate the client checked (name and chain).
  const auto page = [&] {
    beast::ssl_stream<beast::tcp_stream> https(ioc, context);
    https.set_verify_callback(ssl::host_name_verification("127.0.0.1"));
    beast::get_lowest_layer(https).connect(at);
    https.handshake(ssl::stream_base::client);
    http::request<http::empty_body> req{http::verb::get, "/", 11};
    req.set(http::field::host, "127.0.0.1");
    http::write(https, req);
    beast::flat_buffer b;
    http::response<http::string_body> res;
    http::read(https, b, res);
    return res;
  };
  const auto res = page();
  EXPECT_EQ(res.result(), http::status::ok);
  EXPECT_NE(res.body().find("importmap"), std::string::npos);

  // WSS: the scene, then its topology.
  websocket::stream<beast::ssl_stream<beast::tcp_stream>> wss(ioc, context);
  beast::get_lowest_layer(wss).connect(at);
  wss.next_layer().handshake(ssl::stream_base::client);
  wss.read_message_max(64 << 20);
  wss.handshake("127.0.0.1", "/ws");
  beast::flat_buffer b;
  wss.read(b);
  EXPECT_TRUE(wss.got_text());
  EXPECT_EQ(json::parse(beast::buffers_to_string(b.data()))["type"], "scene");

  // Plain HTTP at the TLS port gets no page, and the server goes on serving.
  const std::string plain = get(s.server->port(), "/");
  EXPECT_EQ(plain.find("HTTP/1.1 200"), std::string::npos) << plain.substr(0, 100);
  EXPECT_EQ(page().result(), http::status::ok);
  // A client that trusts another certificate refuses this server's.
  const TlsIdentity stranger = loadOrCreateTlsIdentity(dir / "stranger", {});
  ssl::context wrong = trusting(stranger);
  beast::ssl_stream<beast::tcp_stream> refused(ioc, wrong);
  beast::get_lowest_layer(refused).connect(at);
  beast::error_code ec;
  refused.handshake(ssl::stream_base::client, ec);
  EXPECT_TRUE(ec) << "the handshake succeeded with an untrusted certificate";
}

}  // namespace
}  // namespace vrd
