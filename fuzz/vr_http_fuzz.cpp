// libFuzzer target for the VR server's HTTP requests: the bytes a browser (or anyone) sends, read
// as HttpSession reads them (Beast's request parser, headers only, at most 8 KiB of them) and
// routed as it routes them: a WebSocket upgrade, /status.json, or a file looked up with
// resolveStaticPath in the repository's web/ folder. Besides crashes, sanitizer reports, leaks and
// exceptions, a finding is a file served from outside web/public and three.js's folders.
#include <algorithm>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket/rfc6455.hpp>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string_view>

#include "fuzz_support.h"
#include "vrdeform/web/static_files.h"

namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace fs = std::filesystem;

constexpr std::size_t kMaxRequestHeader = 8 * 1024;  // vr_server.cpp's

bool inside(const fs::path& dir, const fs::path& file) {
  const fs::path root = fs::canonical(dir);
  const auto [r, f] = std::mismatch(root.begin(), root.end(), file.begin(), file.end());
  return r == root.end();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const fs::path web = fs::path(VRDEFORM_SOURCE_DIR) / "web";
  http::request_parser<http::empty_body> parser;
  parser.header_limit(kMaxRequestHeader);
  // Bytes arrive in pieces; the parser is given what has come so far until the header is complete.
  beast::error_code ec;
  std::size_t used = 0;
  for (std::size_t have = std::min<std::size_t>(size, 512); !parser.is_header_done();) {
    used += parser.put(boost::asio::buffer(data + used, have - used), ec);
    if (ec == http::error::need_more) {
      if (have == size) return 0;  // the connection would wait, then time out
      have = std::min(size, have + 512);
      ec = {};
      continue;
    }
    if (ec) return 0;  // answered 400 or 431
  }
  const http::request<http::empty_body>& req = parser.get();
  const std::string_view target(req.target().data(), req.target().size());
  if (beast::websocket::is_upgrade(req)) return 0;  // then only the target "/ws" is compared
  if (req.method() != http::verb::get && req.method() != http::verb::head) return 0;
  if (target.substr(0, target.find('?')) == "/status.json") return 0;
  const std::optional<fs::path> file = vrd::resolveStaticPath(web, target);
  if (file) {
    vrd::fuzz::require(inside(web / "public", *file) || inside(web / "node_modules" / "three", *file));
    (void)vrd::mimeType(*file);
  }
  return 0;
}
