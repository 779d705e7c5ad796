#pragma once
// Sends the haptic signal as Open Sound Control over UDP, for other haptic devices and tools (Max,
// Pure Data, an Arduino bridge, ...). Per sample, with the default prefix "/vrdeform":
//
//   /vrdeform/time     ,d      simulation time (s)
//   /vrdeform/paper    ,f      Algorithm 2's hand value, [0, 1]
//   /vrdeform/force    ,fffff  thumb, index, middle, ring, little, [0, 1] (absent fingers 0)
//   /vrdeform/newtons  ,fffff  the same fingers' contact forces (N)
//
// in that order, in one bundle (timetag "immediately") or, with OscOptions::bundle = false, as four
// datagrams. Messages are encoded with liblo and sent from a non-blocking socket of our own: a
// send never waits (a full socket buffer drops the sample and counts an error) and never throws.

#include <chrono>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "vrdeform/devices/haptic_output.h"
#include "vrdeform/devices/host_port.h"

namespace vrd {

struct OscOptions {
  /// Most samples sent per second of wall-clock time; 0 sends every one. Samples that come sooner
  /// are held back, and only the newest held one can still go out (at the next send() once the
  /// interval has passed, or by flush()); release() discards it.
  double maxRateHz = 0.0;
  /// One bundle per sample (the receiver sees the four messages together); false sends four plain
  /// messages, for receivers that do not unpack bundles.
  bool bundle = true;
};

class OscOutput final : public HapticOutput {
 public:
  /// Resolves `host` (a name, IPv4 or IPv6 address; the first address found that this machine can send to is used)
  /// once, here. Throws vrd::Error for an empty or malformed host, one that does not resolve, a port outside 1..65535,
  /// a prefix that is not "" or "/name[/name...]" of plain characters, or a negative rate.
  OscOutput(std::string_view host, int port, std::string_view prefix = "/vrdeform", const OscOptions& options = {});
  /// Sends zeros unless the last thing sent was already zeros, then closes the socket.
  ~OscOutput() override;
  OscOutput(const OscOutput&) = delete;
  OscOutput& operator=(const OscOutput&) = delete;

  void send(const HapticSample& sample) override;
  /// Sends zeros now (not rate limited) at the last sample's time, and drops any held-back sample.
  void release() override;
  /// Sends the sample the rate limit held back, if there is one.
  void flush();

  std::size_t samplesSent() const { return sent_; }                ///< samples (and releases) that went out whole
  std::size_t errors() const { return errors_; }                   ///< samples that could not be sent
  const std::string& firstError() const { return firstError_; }    ///< "" until a send fails
  const std::string& destination() const { return destination_; }  ///< resolved "address:port"
  const std::string& prefix() const { return prefix_; }

 private:
  void transmit(const HapticSample& sample);
  bool sendDatagram(const void* data, std::size_t size);

  std::string prefix_, destination_;
  std::string timePath_, paperPath_, forcePath_, newtonsPath_;
  OscOptions options_;
  std::chrono::steady_clock::duration interval_{};
  std::chrono::steady_clock::time_point lastSent_{};
  int socket_ = -1;
  std::vector<unsigned char> address_;  // the resolved sockaddr
  std::vector<unsigned char> packet_;   // encode buffer, reused
  HapticSample pending_;
  bool hasPending_ = false, anySent_ = false, zerosLast_ = false;
  double lastTime_ = 0.0;
  std::size_t sent_ = 0, errors_ = 0;
  std::string firstError_;
};

}  // namespace vrd
