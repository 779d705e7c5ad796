#include "tls_front.h"

#include <fmt/format.h>

#include <array>
#include <boost/asio/ssl.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/ssl.hpp>
#include <chrono>
#include <vector>

#include "vrdeform/error.h"

namespace vrd {
namespace {

namespace beast = boost::beast;
namespace net = boost::asio;
namespace ssl = net::ssl;
using tcp = net::ip::tcp;

constexpr auto kHandshakeTimeout = std::chrono::seconds(15);
constexpr std::size_t kChunk = 16 * 1024;

// One client: its TLS stream and the plain connection to the server, bytes pumped both ways; the
// first error or end on either side closes both.
class Tunnel : public std::enable_shared_from_this<Tunnel> {
 public:
  Tunnel(tcp::socket socket, ssl::context& context, tcp::endpoint inner, TlsFront::Log log)
      : outer_(std::move(socket), context),
        inner_(outer_.get_executor()),
        innerEndpoint_(inner),
        log_(std::move(log)) {}

  void start() {
    beast::get_lowest_layer(outer_).expires_after(kHandshakeTimeout);
    outer_.async_handshake(ssl::stream_base::server, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return self->close(fmt::format("TLS handshake: {}", ec.message()));
      beast::get_lowest_layer(self->outer_).expires_never();
      self->inner_.async_connect(self->innerEndpoint_, [self](beast::error_code ec2) {
        if (ec2) return self->close(fmt::format("cannot reach the server: {}", ec2.message()));
        self->pump(self->outer_, self->inner_, self->up_);
        self->pump(self->inner_, self->outer_, self->down_);
      });
    });
  }

  void close(std::string_view why = {}) {
    if (closed_) return;
    closed_ = true;
    if (!why.empty() && log_) log_(fmt::format("vr: tls: {}: {}", peer(), why));
    beast::error_code ec;
    beast::get_lowest_layer(outer_).socket().shutdown(tcp::socket::shutdown_both, ec);
    beast::get_lowest_layer(outer_).close();
    inner_.close();
  }

 private:
  template <typename From, typename To>
  void pump(From& from, To& to, std::array<char, kChunk>& buffer) {
    from.async_read_some(net::buffer(buffer),
                         [self = shared_from_this(), &from, &to, &buffer](beast::error_code ec, std::size_t n) {
                           if (ec) return self->close();
                           net::async_write(to, net::buffer(buffer.data(), n),
                                            [self, &from, &to, &buffer](beast::error_code ec2, std::size_t) {
                                              if (ec2) return self->close();
                                              self->pump(from, to, buffer);
                                            });
                         });
  }

  std::string peer() {
    beast::error_code ec;
    const tcp::endpoint e = beast::get_lowest_layer(outer_).socket().remote_endpoint(ec);
    return ec ? std::string("?") : fmt::format("{}:{}", e.address().to_string(), e.port());
  }

  beast::ssl_stream<beast::tcp_stream> outer_;
  beast::tcp_stream inner_;
  tcp::endpoint innerEndpoint_;
  TlsFront::Log log_;
  std::array<char, kChunk> up_{}, down_{};
  bool closed_ = false;
};

}  // namespace

struct TlsFront::Impl : std::enable_shared_from_this<Impl> {
  net::io_context& ioc;
  ssl::context context{ssl::context::tls_server};
  tcp::acceptor acceptor{ioc};
  tcp::endpoint inner;
  Log log;
  std::vector<std::weak_ptr<Tunnel>> tunnels;
  std::uint16_t port = 0;

  Impl(net::io_context& io, Log l) : ioc(io), log(std::move(l)) {}

  void accept() {
    acceptor.async_accept([self = shared_from_this()](beast::error_code ec, tcp::socket socket) {
      if (!self->acceptor.is_open()) return;
      if (!ec) {
        std::erase_if(self->tunnels, [](const std::weak_ptr<Tunnel>& t) { return t.expired(); });
        auto tunnel = std::make_shared<Tunnel>(std::move(socket), self->context, self->inner, self->log);
        self->tunnels.push_back(tunnel);
        tunnel->start();
      }
      self->accept();
    });
  }
};

TlsFront::TlsFront(net::io_context& ioc, const TlsIdentity& identity, Log log)
    : impl_(std::make_shared<Impl>(ioc, std::move(log))) {
  ssl::context& c = impl_->context;
  c.set_options(ssl::context::default_workarounds | ssl::context::no_sslv2 | ssl::context::no_sslv3 |
                ssl::context::no_tlsv1 | ssl::context::no_tlsv1_1 | ssl::context::single_dh_use);
  beast::error_code ec;
  c.use_certificate_chain(net::buffer(identity.certificatePem), ec);
  if (!ec) c.use_private_key(net::buffer(identity.privateKeyPem), ssl::context::pem, ec);
  if (ec) throw Error(fmt::format("tls: the certificate or key cannot be used: {}", ec.message()));
}

TlsFront::~TlsFront() = default;

void TlsFront::start(const tcp::endpoint& listen, const tcp::endpoint& inner) {
  Impl& s = *impl_;
  s.inner = inner;
  beast::error_code ec;
  s.acceptor.open(listen.protocol(), ec);
  if (!ec) s.acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) s.acceptor.bind(listen, ec);
  if (!ec) s.acceptor.listen(net::socket_base::max_listen_connections, ec);
  if (ec)
    throw Error(fmt::format("cannot listen on {}:{}: {}", listen.address().to_string(), listen.port(), ec.message()));
  s.port = s.acceptor.local_endpoint().port();
  s.accept();
}

void TlsFront::stop() {
  beast::error_code ec;
  impl_->acceptor.close(ec);
  for (const std::weak_ptr<Tunnel>& w : impl_->tunnels)
    if (const auto t = w.lock()) t->close();
  impl_->tunnels.clear();
}

std::uint16_t TlsFront::port() const { return impl_->port; }

}  // namespace vrd
