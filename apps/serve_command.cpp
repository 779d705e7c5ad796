#include "serve_command.h"

#include <arpa/inet.h>
#include <fmt/format.h>
#include <ifaddrs.h>
#include <netinet/in.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "build_observer.h"
#include "vrdeform/devices/glove_link.h"
#include "vrdeform/devices/stop_signals.h"
#include "vrdeform/error.h"
#include "vrdeform/scene/scene_library.h"
#include "vrdeform/web/static_files.h"
#include "vrdeform/web/vr_server.h"

namespace vrd {
namespace {

struct ServeArgs {
  std::string scene, weart;
  ServeOptions serve;
  double seconds = 0.0;  // 0: until Ctrl-C
};

// The machine's IPv4 addresses other than loopback: what a headset on the LAN opens.
std::vector<std::string> lanAddresses() {
  std::vector<std::string> out;
  ifaddrs* list = nullptr;
  if (::getifaddrs(&list) != 0) return out;
  for (const ifaddrs* a = list; a; a = a->ifa_next) {
    if (!a->ifa_addr || a->ifa_addr->sa_family != AF_INET) continue;
    char text[INET_ADDRSTRLEN] = {};
    const auto* in = reinterpret_cast<const sockaddr_in*>(a->ifa_addr);
    if (::inet_ntop(AF_INET, &in->sin_addr, text, sizeof text) && std::string_view(text).substr(0, 4) != "127.")
      out.emplace_back(text);
  }
  ::freeifaddrs(list);
  return out;
}

}  // namespace

void printAddresses(const ServeOptions& a, std::uint16_t port) {
  const bool everywhere = a.bind == "0.0.0.0" || a.bind == "::";
  const std::string local = everywhere || a.bind == "127.0.0.1" ? "127.0.0.1" : a.bind;
  const char* scheme = a.tls ? "https" : "http";
  fmt::print("serving on {}://{}:{}/ (Ctrl-C stops)\n", scheme, local, port);
  if (local == "127.0.0.1")
    fmt::print("  a Quest over USB: adb reverse tcp:{0} tcp:{0}, then open {1}://localhost:{0}/ in its browser\n", port,
               scheme);
  if (everywhere)
    for (const std::string& ip : lanAddresses())
      fmt::print("  on the local network: {}://{}:{}/{}\n", scheme, ip, port,
                 a.tls ? " (accept the certificate once: its fingerprint is above)"
                       : " (not a secure context, so no WebXR: --tls, or see docs/vr.md)");
  std::fflush(stdout);
}

VrServerSettings vrServerSettings(const ServeOptions& a) {
  const std::filesystem::path web = webFolder();
  if (!hasThreeJs(web))
    fmt::print(stderr,
               "vrdeform: warning: {}/node_modules/three is missing (scripts/install-web.sh installs it); "
               "the page cannot draw without it\n",
               web.string());
  VrServerSettings vs;
  vs.bind = a.bind;
  vs.port = a.port;
  vs.frameRate = a.frameRate;
  if (a.tls) {
    const std::filesystem::path folder = a.tlsFolder.empty() ? defaultTlsFolder() : std::filesystem::path(a.tlsFolder);
    vs.tls = loadOrCreateTlsIdentity(folder, lanAddresses());
    fmt::print(
        "tls: {} certificate {}/cert.pem\n  SHA-256 fingerprint {}\n  Chromium: "
        "--ignore-certificate-errors-spki-list={}\n",
        vs.tls->created ? "made a self-signed" : "the self-signed", folder.string(), vs.tls->fingerprint,
        vs.tls->spkiHash);
  }
  return vs;
}

void addServeOptions(CLI::App& cmd, ServeOptions& o) {
  cmd.add_option("--port", o.port, "TCP port of the page and its WebSocket (0: any free one)")->capture_default_str();
  cmd.add_option("--bind", o.bind,
                 "Address to listen on; 0.0.0.0 serves the local network (prints the addresses to open)")
      ->capture_default_str();
  cmd.add_flag("--tls", o.tls,
               "Serve HTTPS and WSS (WebXR on the local network needs them) with a self-signed certificate, made "
               "on first use (its fingerprint printed)");
  cmd.add_option("--tls-dir", o.tlsFolder, "Where the certificate and key are kept (default: ~/.config/vrdeform/tls)");
  cmd.add_option("--fps", o.frameRate, "Frames per second sent to the viewers at most")
      ->check(CLI::Range(1.0, 1000.0))
      ->capture_default_str();
}

namespace {

int serve(const ServeArgs& a) {
  const SceneSpec spec = loadSceneByName(a.scene);
  printSceneTitle(spec);
  std::fflush(stdout);
  const StopSignals signals;
  BuiltScene scene = buildScene(spec, commandObserver(signals, false));
  VrServerSettings vs = vrServerSettings(a.serve);
  vs.hand.park = scene.bodies.front().top + Vec3(0.0f, 0.15f, 0.0f);
  const float radius = scene.session.hand.geometry.fingertipRadius;
  std::optional<LiveHandInput> hand;
  if (spec.hand.enabled) hand.emplace(xrParkedFrame(vs.hand, radius));

  std::optional<GloveLink> glove;
  SimulationLoopSettings ls;
  if (!a.weart.empty()) {
    if (!spec.hand.enabled) throw Error(fmt::format("scene {} has no hand for the glove", spec.name));
    glove.emplace(a.weart, scene.session.hand, scene.bodies.front().top);
    ls.outputs.push_back(&glove->output());
    vs.gloveClosure = [&glove] { return glove->closure(Finger::Index); };
    vs.gloveConnected = [&glove] { return glove->connected(); };
  }
  ls.input = hand ? &*hand : nullptr;
  SimulationLoop loop(scene, ls);
  VrServer server(loop, scene, webFolder(), vs, hand ? &*hand : nullptr);
  server.start();
  loop.start();
  fmt::print("simulating at {:g} Hz, {} frames/s to viewers; the page: {}\n", 1.0 / loop.period(), a.serve.frameRate,
             (webFolder() / "public").string());
  printAddresses(a.serve, server.port());

  const auto start = std::chrono::steady_clock::now();
  while (loop.running() && !signals.requested()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (glove) glove->reportEvents();
    if (a.seconds > 0 && std::chrono::steady_clock::now() - start > std::chrono::duration<double>(a.seconds)) break;
  }
  server.stop();
  int status = 0;
  try {
    loop.stop();
  } catch (const std::exception& e) {
    fmt::print(stderr, "vrdeform: the simulation failed: {}\n", e.what());
    status = 1;
  }
  if (glove) glove->shutdown();
  const VrServerStats s = server.stats();
  const LoopStats ls2 = loop.stats();
  fmt::print(
      "\nserved {} viewer(s): {} frames sent, {} skipped for slow viewers, {} MB; {} inputs, {} messages rejected, "
      "{} viewer(s) dropped\n",
      s.viewersTotal, s.framesSent, s.framesSkipped, double(s.bytesSent) / 1e6, s.inputs, s.messagesRejected,
      s.viewersDropped);
  fmt::print("simulation: {} steps at {:.1f} Hz, {} overruns, step {:.3f} ms mean, {:.3f} ms p99\n", ls2.steps,
             ls2.achievedRate, ls2.overruns, ls2.stepMs.mean, ls2.stepMs.p99);
  return status;
}

}  // namespace

std::function<int()> addServeCommand(CLI::App& app) {
  auto a = std::make_shared<ServeArgs>();
  CLI::App* serve = app.add_subcommand(
      "serve", "Run a scene in real time and serve the VR page (WebXR) on which a headset shows and drives it");
  serve->add_option("scene", a->scene, "A built-in scene (`vrdeform scenes`) or a scene file (.toml)")->required();
  addServeOptions(*serve, a->serve);
  serve->add_option("--seconds", a->seconds, "Stop after this many seconds (default: at Ctrl-C)")
      ->check(CLI::Range(0.0, 1e9));
  serve
      ->add_option("--weart", a->weart,
                   "Send the forces to a WEART glove and close the hand with it: HOST[:PORT] of the middleware "
                   "(default port 13031); without a glove the controllers vibrate with the force")
      ->check(CLI::Validator(weartEndpointError, "HOST[:PORT]"));
  return [a, serve]() -> int {
    if (*serve) return vrd::serve(*a);
    return 0;
  };
}

}  // namespace vrd
