// vrdeform-fake-weart: a fake WEART middleware on 127.0.0.1 for trying a client without a glove.
// Prints "listening on 127.0.0.1:PORT" first, then logs every command it receives, with the time
// since it started, until SIGINT / SIGTERM.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "vrdeform/devices/stop_signals.h"
#include "vrdeform/error.h"
#include "vrdeform/testing/fake_middleware.h"

namespace {

using Clock = std::chrono::steady_clock;

// Log lines from the fake's thread and the main loop, one at a time, flushed so a script sees them.
class Log {
 public:
  explicit Log(std::FILE* out) : out_(out), start_(Clock::now()) {}
  void line(Clock::time_point when, std::string_view text) {
    const double t = std::chrono::duration<double>(when - start_).count();
    std::lock_guard lock(mutex_);
    fmt::print(out_, "{:10.4f} {}\n", t, text);
    std::fflush(out_);
  }

 private:
  std::mutex mutex_;
  std::FILE* out_;
  Clock::time_point start_;
};

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"vrdeform-fake-weart: a fake WEART middleware (TouchDIVER G1 or Pro) on 127.0.0.1"};
  int port = 13031;
  std::string script, logPath;
  bool pro = false;
  double disconnectAfter = 0, garbageEvery = 0, seconds = 0;
  const vrd::weart::FakeMiddlewareSettings defaults;
  double statusPeriod = std::chrono::duration<double>(defaults.statusPeriod).count();
  int slowReader = 0, startError = 0;
  app.add_option("--port", port, "TCP port (0: any free port; the first line says which)")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  app.add_option("--script", script, "Tracking keyframes: lines 't thumb index middle [ring little]', closures 0-1")
      ->check(CLI::ExistingFile);
  app.add_option("--log", logPath, "Write the command log to this file instead of stdout");
  app.add_flag("--pro", pro, "TouchDIVER Pro / WeArtApp flavour (WA_STATUS, TRACKING_BENDING_G2)");
  app.add_option("--status-period", statusPeriod,
                 "Push the status and device status every this many seconds, besides on connect and on "
                 "change (0: only then)")
      ->check(CLI::Range(0.0, 3600.0))
      ->capture_default_str();
  app.add_option("--disconnect-after", disconnectAfter, "Drop each client this many seconds after it connects")
      ->check(CLI::Range(0.001, 1e6));
  app.add_option("--slow-reader", slowReader, "Sleep this many milliseconds before each read")
      ->check(CLI::Range(1, 10000));
  app.add_option("--garbage-every", garbageEvery, "Send a malformed frame every this many seconds")
      ->check(CLI::Range(0.001, 1e6));
  app.add_option("--start-error", startError, "Refuse StartFromClient with this status code (e.g. 101)")
      ->check(CLI::Range(1, 999));
  app.add_option("--seconds", seconds, "Exit after this many seconds (default: run until SIGINT / SIGTERM)")
      ->check(CLI::Range(0.001, 1e9));
  CLI11_PARSE(app, argc, argv);

  try {
    std::unique_ptr<std::FILE, FileCloser> logFile;
    if (!logPath.empty()) {
      logFile.reset(std::fopen(logPath.c_str(), "w"));
      if (!logFile) throw vrd::Error("cannot write " + logPath);
    }
    Log log(logFile ? logFile.get() : stdout);

    vrd::weart::FakeMiddlewareSettings settings;
    settings.port = static_cast<std::uint16_t>(port);
    settings.pro = pro;
    // A period shorter than a millisecond still repeats: it rounds up, never to 0 (off).
    settings.statusPeriod = std::chrono::ceil<std::chrono::milliseconds>(std::chrono::duration<double>(statusPeriod));
    if (!script.empty()) settings.tracking = vrd::weart::TrackingScript::load(script).source();
    settings.onCommand = [&log](const vrd::weart::ReceivedCommand& c) {
      log.line(c.time, vrd::weart::describe(c.command));
    };
    settings.onNote = [&log](std::string_view text) { log.line(Clock::now(), fmt::format("# {}", text)); };

    vrd::StopSignals signals;
    vrd::weart::FakeMiddleware fake(settings);
    fmt::print("listening on 127.0.0.1:{}\n", fake.port());
    std::fflush(stdout);
    if (slowReader > 0) fake.setReadDelay(std::chrono::milliseconds(slowReader));
    if (startError > 0) fake.setStartError(startError);
    fake.start();

    const Clock::time_point started = Clock::now();
    int connection = 0;
    Clock::time_point connectedAt = started, lastGarbage = started;
    bool dropped = false;
    while (!signals.requested()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      const Clock::time_point now = Clock::now();
      if (seconds > 0 && now - started >= std::chrono::duration<double>(seconds)) break;
      if (fake.connections() != connection) {
        connection = fake.connections();
        connectedAt = now;
        dropped = false;
      }
      if (disconnectAfter > 0 && !dropped && fake.clientConnected() &&
          now - connectedAt >= std::chrono::duration<double>(disconnectAfter)) {
        fake.dropClient();
        dropped = true;
      }
      if (garbageEvery > 0 && now - lastGarbage >= std::chrono::duration<double>(garbageEvery)) {
        lastGarbage = now;
        if (fake.clientConnected()) {
          fake.sendRaw("Tracking:TrackType1:1:2~{\"type\":\"MW_STATUS\",\"ts\":~\x01\x7f\xff~");
          log.line(now, "# sent garbage");
        }
      }
    }
    if (signals.requested()) log.line(Clock::now(), fmt::format("# signal {}: stopping", signals.signal()));
    fake.stop();
  } catch (const vrd::Error& e) {
    fmt::print(stderr, "vrdeform-fake-weart: {}\n", e.what());
    return 2;
  }
  return 0;
}
