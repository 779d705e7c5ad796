#pragma once
// TLS in front of the VR server (`vrdeform serve --tls`): accepts TLS connections on the public
// address, completes the handshake (within a timeout) and tunnels each connection's bytes to the
// plain server on a loopback port, so that HTTPS and WSS reach the same handlers as HTTP and WS.
// Runs on the server's I/O context and thread.

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "vrdeform/web/tls_identity.h"

namespace vrd {

class TlsFront {
 public:
  using Log = std::function<void(std::string_view)>;
  /// Throws vrd::Error when the certificate or key cannot be used.
  TlsFront(boost::asio::io_context& ioc, const TlsIdentity& identity, Log log);
  ~TlsFront();
  TlsFront(const TlsFront&) = delete;
  TlsFront& operator=(const TlsFront&) = delete;

  /// Listens on `listen` and tunnels to `inner`. Throws vrd::Error when it cannot listen.
  void start(const boost::asio::ip::tcp::endpoint& listen, const boost::asio::ip::tcp::endpoint& inner);
  /// Stops accepting and closes every tunnel (on the I/O thread).
  void stop();
  std::uint16_t port() const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace vrd
