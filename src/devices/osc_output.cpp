#include "vrdeform/devices/osc_output.h"

#include "endpoint.h"
#include "vrdeform/core/posix_fd.h"

#include <fmt/format.h>
#include <lo/lo.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <memory>
#include <system_error>
#include <utility>

#include "vrdeform/error.h"

namespace vrd {

namespace {

/// "" or "/name[/name...]" with printable characters that OSC does not reserve for patterns.
bool validPrefix(std::string_view prefix) {
  if (prefix.empty()) return true;
  if (prefix.front() != '/' || prefix.back() == '/' || prefix.find("//") != std::string_view::npos) return false;
  for (const char c : prefix)
    if (c <= ' ' || c > '~' || std::strchr("#*,?[]{}", c) != nullptr) return false;
  return true;
}

/// A liblo message that we hold one reference to (liblo counts them; a bundle holds another).
class Message {
 public:
  Message() : m_(lo_message_new()) {
    if (m_) lo_message_incref(m_);
  }
  ~Message() {
    if (m_) lo_message_free(m_);
  }
  Message(const Message&) = delete;
  Message& operator=(const Message&) = delete;
  lo_message get() const { return m_; }

 private:
  lo_message m_;
};

struct AddrInfoDeleter {
  void operator()(addrinfo* a) const { ::freeaddrinfo(a); }
};

}  // namespace

OscOutput::OscOutput(std::string_view host, int port, std::string_view prefix, const OscOptions& options)
    : prefix_(prefix), options_(options) {
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  if (!validHost(host)) throw Error(fmt::format("OSC output: \"{}\" is not a host name or address", host));
  if (port < 1 || port > 65535) throw Error(fmt::format("OSC output: port {} is not in 1..65535", port));
  if (!validPrefix(prefix))
    throw Error(
        fmt::format("OSC output: prefix \"{}\" must be empty or /name[/name...] without spaces or #*,?[]{{}}", prefix));
  if (!std::isfinite(options.maxRateHz) || options.maxRateHz < 0.0)
    throw Error(fmt::format("OSC output: maxRateHz {} must be finite and >= 0 (0: unlimited)", options.maxRateHz));
  if (options.maxRateHz > 0.0)
    interval_ = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(1.0 / options.maxRateHz));

  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_DGRAM;
  hints.ai_protocol = IPPROTO_UDP;
  hints.ai_flags = AI_NUMERICSERV;
  const std::string hostText(host), portText = std::to_string(port);
  addrinfo* found = nullptr;
  const int rc = ::getaddrinfo(hostText.c_str(), portText.c_str(), &hints, &found);
  const std::unique_ptr<addrinfo, AddrInfoDeleter> owner(found);
  if (rc != 0 || found == nullptr)
    throw Error(fmt::format("OSC output: cannot resolve \"{}\": {}", hostText,
                            rc == EAI_SYSTEM ? errnoText(errno) : std::string(::gai_strerror(rc))));

  // The first address we can open a socket for (a host may list IPv6 first on a machine without it).
  int socketError = 0;
  for (; found != nullptr; found = found->ai_next) {
    socket_ = ::socket(found->ai_family, found->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, found->ai_protocol);
    if (socket_ >= 0) break;
    socketError = errno;
  }
  if (socket_ < 0)
    throw Error(fmt::format("OSC output: cannot open a UDP socket for \"{}\": {}", hostText, errnoText(socketError)));
  const auto* bytes = reinterpret_cast<const unsigned char*>(found->ai_addr);
  address_.assign(bytes, bytes + found->ai_addrlen);

  char numeric[NI_MAXHOST] = "?";
  ::getnameinfo(found->ai_addr, found->ai_addrlen, numeric, sizeof numeric, nullptr, 0, NI_NUMERICHOST);
  destination_ =
      found->ai_family == AF_INET6 ? fmt::format("[{}]:{}", numeric, port) : fmt::format("{}:{}", numeric, port);

  timePath_ = prefix_ + "/time";
  paperPath_ = prefix_ + "/paper";
  forcePath_ = prefix_ + "/force";
  newtonsPath_ = prefix_ + "/newtons";
}

OscOutput::~OscOutput() {
  if (anySent_ && !zerosLast_) release();
  ::close(socket_);
}

void OscOutput::send(const HapticSample& sample) {
  const HapticSample s = sanitised(sample);
  lastTime_ = s.time;
  if (interval_.count() > 0) {
    const auto now = std::chrono::steady_clock::now();
    if (anySent_ && now - lastSent_ < interval_) {
      pending_ = s;  // only the newest held-back sample may still go out
      hasPending_ = true;
      return;
    }
    lastSent_ = now;
  }
  hasPending_ = false;
  transmit(s);
  zerosLast_ = false;
}

void OscOutput::flush() {
  if (!hasPending_) return;
  hasPending_ = false;
  lastSent_ = std::chrono::steady_clock::now();
  transmit(pending_);
  zerosLast_ = false;
}

void OscOutput::release() {
  hasPending_ = false;  // never send a value from before the release after it
  HapticSample zero;
  zero.time = lastTime_;
  transmit(zero);
  zerosLast_ = true;
}

void OscOutput::transmit(const HapticSample& s) {
  anySent_ = true;
  const Message time, paper, force, newtons;
  bool ok = time.get() && paper.get() && force.get() && newtons.get();
  if (ok) {
    ok = lo_message_add_double(time.get(), s.time) == 0 && lo_message_add_float(paper.get(), s.paper) == 0;
    for (int f = 0; f < kFingerCount; ++f)
      ok = ok && lo_message_add_float(force.get(), s.force[f]) == 0 &&
           lo_message_add_float(newtons.get(), s.newtons[f]) == 0;
  }
  const std::array<std::pair<const std::string*, lo_message>, 4> messages{{{&timePath_, time.get()},
                                                                           {&paperPath_, paper.get()},
                                                                           {&forcePath_, force.get()},
                                                                           {&newtonsPath_, newtons.get()}}};

  if (ok && options_.bundle) {
    lo_bundle bundle = lo_bundle_new(lo_timetag{0U, 1U});  // timetag 1: "immediately" (LO_TT_IMMEDIATE)
    ok = bundle != nullptr;
    for (const auto& [path, message] : messages) ok = ok && lo_bundle_add_message(bundle, path->c_str(), message) == 0;
    if (ok) {
      std::size_t size = lo_bundle_length(bundle);
      packet_.resize(size);
      ok = lo_bundle_serialise(bundle, packet_.data(), &size) != nullptr;
      if (ok) ok = sendDatagram(packet_.data(), size);
    }
    if (bundle) lo_bundle_free_recursive(bundle);  // drops the bundle's references to the messages
  } else if (ok) {
    for (const auto& [path, message] : messages) {
      std::size_t size = lo_message_length(message, path->c_str());
      packet_.resize(size);
      ok = ok && lo_message_serialise(message, path->c_str(), packet_.data(), &size) != nullptr &&
           sendDatagram(packet_.data(), size);
    }
  }
  if (ok) {
    ++sent_;
    return;
  }
  ++errors_;
  if (firstError_.empty())
    firstError_ = fmt::format("OSC to {}: cannot encode a message (out of memory)", destination_);
}

bool OscOutput::sendDatagram(const void* data, std::size_t size) {
  ssize_t n;
  do {
    n = ::sendto(socket_, data, size, MSG_NOSIGNAL, reinterpret_cast<const sockaddr*>(address_.data()),
                 static_cast<socklen_t>(address_.size()));
  } while (n < 0 && errno == EINTR);
  if (n == static_cast<ssize_t>(size)) return true;
  if (firstError_.empty())
    firstError_ = fmt::format("OSC to {}: {}", destination_, n < 0 ? errnoText(errno) : "short send");
  return false;
}

}  // namespace vrd
