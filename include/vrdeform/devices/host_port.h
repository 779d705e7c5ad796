#pragma once
// A network address as users type it: "HOST:PORT" (IPv6 as "[::1]:9000"), for the OSC output and
// the study files that name one.

#include <string>
#include <string_view>

namespace vrd {

struct HostPort {
  std::string host;
  int port = 0;
};

/// Splits "HOST:PORT" (IPv6 as "[::1]:9000") and checks both parts; throws vrd::Error without a
/// host or a port in 1..65535.
HostPort parseHostPort(std::string_view text);

}  // namespace vrd
