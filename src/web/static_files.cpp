#include "vrdeform/web/static_files.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

#include "vrdeform/core/installed_data.h"
#include "vrdeform/error.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;

bool hasPage(const fs::path& dir) {
  std::error_code ec;
  return !dir.empty() && fs::is_regular_file(dir / "public" / "index.html", ec);
}

int hexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// The decoded segments of an absolute path; nullopt when any is unsafe or malformed.
std::optional<std::vector<std::string>> segments(std::string_view path) {
  if (path.empty() || path.front() != '/') return std::nullopt;
  std::vector<std::string> out;
  std::string current;
  for (std::size_t i = 1; i <= path.size(); ++i) {
    if (i == path.size() || path[i] == '/') {
      if (current.empty() && i < path.size()) return std::nullopt;  // "//"
      if (current == "." || current == "..") return std::nullopt;
      out.push_back(std::move(current));
      current.clear();
      continue;
    }
    char c = path[i];
    if (c == '%') {
      if (i + 2 >= path.size() || hexDigit(path[i + 1]) < 0 || hexDigit(path[i + 2]) < 0) return std::nullopt;
      c = char(hexDigit(path[i + 1]) * 16 + hexDigit(path[i + 2]));
      i += 2;
      if (c == '/') return std::nullopt;  // an encoded separator
    }
    if (c == '\0' || c == '\\' || static_cast<unsigned char>(c) < 0x20) return std::nullopt;
    current += c;
  }
  return out;  // the last one is empty for a path ending in '/'
}

// `relative` under `base`, provided the file it names (links resolved) is still under base.
std::optional<fs::path> under(const fs::path& base, const fs::path& relative) {
  std::error_code ec;
  const fs::path root = fs::canonical(base, ec);
  if (ec) return std::nullopt;
  const fs::path file = fs::canonical(base / relative, ec);
  if (ec || !fs::is_regular_file(file, ec)) return std::nullopt;
  const auto [r, f] = std::mismatch(root.begin(), root.end(), file.begin(), file.end());
  if (r != root.end()) return std::nullopt;
  return file;
}

}  // namespace

fs::path webFolder() {
  if (const char* env = std::getenv("VRDEFORM_WEB"); env && *env) {
    if (!hasPage(env)) throw Error(fmt::format("VRDEFORM_WEB={}: no public/index.html there", env));
    return env;
  }
  for (const fs::path& dir : {fs::path(VRDEFORM_SOURCE_WEB), installedData("web")})
    if (hasPage(dir)) return dir;
  throw Error(fmt::format("the VR page is missing (looked in {} and {}); set VRDEFORM_WEB to its folder",
                          VRDEFORM_SOURCE_WEB, installedData("web").string()));
}

bool hasThreeJs(const fs::path& web) {
  std::error_code ec;
  return fs::is_regular_file(web / "node_modules" / "three" / "build" / "three.module.js", ec);
}

std::optional<fs::path> resolveStaticPath(const fs::path& web, std::string_view target) {
  const std::string_view path = target.substr(0, target.find_first_of("?#"));
  const auto parts = segments(path);
  if (!parts) return std::nullopt;
  fs::path relative;
  for (const std::string& s : *parts) relative /= s;
  if (parts->back().empty()) relative /= "index.html";
  const fs::path three = web / "node_modules" / "three";
  if (parts->size() >= 3 && (*parts)[0] == "three") {
    const fs::path inside = relative.lexically_relative("three");
    if ((*parts)[1] == "build") return under(three / "build", inside.lexically_relative("build"));
    if ((*parts)[1] == "examples" && (*parts)[2] == "jsm")
      return under(three / "examples" / "jsm", inside.lexically_relative("examples/jsm"));
    return std::nullopt;
  }
  return under(web / "public", relative);
}

std::string_view mimeType(const fs::path& file) {
  const std::string ext = file.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json") return "application/json";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".png") return "image/png";
  if (ext == ".ico") return "image/x-icon";
  if (ext == ".txt" || ext == ".md") return "text/plain; charset=utf-8";
  return "application/octet-stream";
}

}  // namespace vrd
