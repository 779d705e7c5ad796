#pragma once
// A WEART glove as the hand of a simulation (the commands' `--weart HOST:PORT`, Python's
// Scene.run(weart=...)): its finger closures drive a palm-down hand held over a point of the body,
// each finger's force goes back to its thimble, and the loop is paced to real time. The client's
// thread does the I/O, so a missing or slow glove never stalls the simulation; every thimble is
// released at shutdown (and by the client's watchdog, signals and destructor).

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "vrdeform/devices/glove_input.h"
#include "vrdeform/devices/haptic_output.h"
#include "vrdeform/devices/weart_client.h"
#include "vrdeform/haptics/haptic_model.h"

namespace vrd {

/// For a command's --weart option (a CLI11 validator): "" for an endpoint weart::parseEndpoint takes,
/// else why not, so that a malformed one is refused at once instead of retried.
std::string weartEndpointError(const std::string& endpoint);

/// Where a link's news goes: a line (connection changes, errors) and whether it is an error.
using GloveNews = std::function<void(std::string_view line, bool error)>;
/// The commands' news: errors to stderr, the rest to stdout, each line prefixed "glove: ".
void printGloveNews(std::string_view line, bool error);

class GloveLink {
 public:
  /// Connects in the background to `endpoint` (HOST[:PORT]) with a thimble per finger of `hand`;
  /// the wrist is held palm down over `point`, so that closing the hand brings the fingertips onto it.
  GloveLink(const std::string& endpoint, const HandRigSettings& hand, const Vec3& point,
            GloveNews news = printGloveNews);

  HandInput& input() { return *input_; }
  const std::string& name() const { return name_; }
  /// After the step that ends at simulation time `time`: publishes the forces, passes on the
  /// client's news and sleeps until that time has passed on the wall clock (from the first call).
  void afterStep(const HapticFrame& frame, double time);
  /// The thimbles as one of a `SimulationLoop`'s outputs (viewer, VR server): each step's forces,
  /// published from the loop's thread without waiting, which also keeps the watchdog quiet.
  HapticOutput& output() { return output_; }
  /// Passes on the client's news (connection changes, errors) since the last call.
  void reportEvents();
  /// The glove's latest closure of `finger` in [0, 1]; nullopt before its first tracking frame.
  std::optional<float> closure(Finger finger) const;
  /// Whether the middleware session runs, so that forces reach the glove.
  bool connected() const;
  /// Releases the glove and stops the client (also done by the destructor).
  void shutdown() { client_.shutdown(); }

 private:
  struct Output final : HapticOutput {
    explicit Output(weart::Client& c) : client(c) {}
    void send(const HapticSample& sample) override { client.publishForces(sample.force); }
    void release() override { client.publishForces({}); }
    weart::Client& client;
  };

  weart::Client client_;
  GloveNews news_;
  Output output_{client_};
  std::optional<weart::GloveInput> input_;
  std::string name_;
  std::optional<std::chrono::steady_clock::time_point> start_;
};

/// A palm-down wrist over `point`: an open hand is clear of it, and closing the index lowers its
/// fingertip onto it (it reaches lowest near closure 0.5, pressing half a fingertip radius deep).
Eigen::Isometry3f wristAbove(const Vec3& point, const HandGeometry& hand);

}  // namespace vrd
