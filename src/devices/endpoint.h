#pragma once
// Network endpoints as users type them, shared by the WEART client and the OSC output (internal).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace vrd {

/// A host name (letters, digits, '.', '-', '_') or an IPv6 literal (with an optional %zone):
/// checked before any name lookup, so that a typo fails at once instead of after a DNS timeout.
bool validHost(std::string_view host);

struct Endpoint {
  std::string host;                   ///< "" when left out (":PORT")
  std::optional<std::uint16_t> port;  ///< nullopt when left out
};

/// Splits "HOST:PORT", "HOST", ":PORT", "[IPv6]:PORT", "[IPv6]" or a bare IPv6 address and checks
/// both parts (port 1..65535). On failure returns nullopt and says why in `why`.
std::optional<Endpoint> splitEndpoint(std::string_view text, std::string& why);

}  // namespace vrd
