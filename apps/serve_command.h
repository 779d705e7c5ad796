#pragma once
// `vrdeform serve SCENE`: runs a scene's simulation loop in real time and serves the VR page, so
// that a headset (or any browser) shows the deforming bodies and drives the hand (docs/vr.md).

#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <string>

#include "vrdeform/web/vr_server.h"

namespace vrd {

/// How the VR page is served (`serve`, `study run --vr`).
struct ServeOptions {
  std::string bind = "127.0.0.1", tlsFolder;
  bool tls = false;
  std::uint16_t port = 8080;
  double frameRate = 72.0;
};

/// Adds --port, --bind, --tls, --tls-dir and --fps to `cmd`.
void addServeOptions(CLI::App& cmd, ServeOptions& o);

/// The VR server's settings for `o`: with --tls the certificate made or read (its fingerprint
/// printed). Warns when the web folder lacks three.js.
VrServerSettings vrServerSettings(const ServeOptions& o);

/// Prints the addresses a browser or a headset opens.
void printAddresses(const ServeOptions& o, std::uint16_t port);

/// Adds the `serve` command to `app`. The returned function runs it and returns the exit code (0
/// fine, 1 the simulation failed); vrd::Error (bad input) propagates for the caller to report as 2.
std::function<int()> addServeCommand(CLI::App& app);

}  // namespace vrd
