#include "endpoint.h"

#include <fmt/format.h>

#include <arpa/inet.h>

#include <algorithm>
#include <charconv>
#include <string>

#include "vrdeform/devices/host_port.h"
#include "vrdeform/error.h"

namespace vrd {
namespace {

bool validHostName(std::string_view host) {
  if (host.empty() || host.size() > 253) return false;
  return std::all_of(host.begin(), host.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '-' ||
           c == '_';
  });
}

// An IPv6 address as inet_pton reads it (so "::::" is not one), with an optional %zone.
bool validIpv6(std::string_view host) {
  const std::size_t zone = host.find('%');
  const std::string address(host.substr(0, zone));
  in6_addr parsed{};
  if (::inet_pton(AF_INET6, address.c_str(), &parsed) != 1) return false;
  return zone == std::string_view::npos || validHostName(host.substr(zone + 1));
}

std::optional<std::uint16_t> parsePort(std::string_view text) {
  if (text.empty() || text.size() > 5) return std::nullopt;
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || value == 0 || value > 65535) return std::nullopt;
  return std::uint16_t(value);
}

}  // namespace

bool validHost(std::string_view host) { return validHostName(host) || validIpv6(host); }

std::optional<Endpoint> splitEndpoint(std::string_view text, std::string& why) {
  if (text.empty()) return why = "empty", std::nullopt;
  std::string_view host, port;
  bool hasPort = false;
  if (text.front() == '[') {
    const std::size_t close = text.find(']');
    if (close == std::string_view::npos) return why = "no ']' after the IPv6 address", std::nullopt;
    host = text.substr(1, close - 1);
    const std::string_view rest = text.substr(close + 1);
    if (!rest.empty()) {
      if (rest.front() != ':') return why = "unexpected text after ']'", std::nullopt;
      port = rest.substr(1);
      hasPort = true;
    }
    if (!validIpv6(host)) return why = "not an IPv6 address inside [ ]", std::nullopt;
  } else if (std::count(text.begin(), text.end(), ':') > 1) {
    host = text;  // a bare IPv6 address, no port
    if (!validIpv6(host)) return why = "not a host name or an IPv6 address", std::nullopt;
  } else {
    const std::size_t colon = text.find(':');
    host = text.substr(0, colon);
    if (colon != std::string_view::npos) port = text.substr(colon + 1), hasPort = true;
    if (!host.empty() && !validHostName(host)) return why = "bad host name", std::nullopt;
  }
  if (hasPort && port.empty()) return why = "empty port", std::nullopt;
  if (host.empty() && !hasPort) return why = "no host and no port", std::nullopt;
  Endpoint out{std::string(host), std::nullopt};
  if (hasPort && !(out.port = parsePort(port))) return why = "the port must be a number from 1 to 65535", std::nullopt;
  return out;
}

HostPort parseHostPort(std::string_view text) {
  std::string why;
  const std::optional<Endpoint> e = splitEndpoint(text, why);
  if (!e) throw Error(fmt::format("\"{}\": {} (expected HOST:PORT or [IPv6]:PORT)", text, why));
  if (e->host.empty() || !e->port) throw Error(fmt::format("\"{}\": expected HOST:PORT or [IPv6]:PORT", text));
  return {e->host, *e->port};
}

}  // namespace vrd
