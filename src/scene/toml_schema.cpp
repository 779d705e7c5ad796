#include "scene/toml_schema.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>

namespace vrd::schema {
namespace {

// Optimal string alignment distance: insertions, deletions, substitutions and swaps of neighbours
// (the usual typos) cost 1 each.
std::size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i)
    for (std::size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] != b[j - 1])});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

[[noreturn]] void syntaxError(const std::string& source, const toml::parse_error& e) {
  const Line line = e.source().begin.line ? e.source().begin.line : 1;
  throw Error(fmt::format("{}:{}: TOML syntax: {}", source, line, printable(e.description())));
}

// toml++ 3.3 recurses once per level of dotted-key nesting (`a.b.c = 1`, `[a.b.c]`) with no limit
// (arrays and inline tables have one, 256), so a key nested 100000 deep overflows the stack (about
// 30000 levels fit in 8 MiB). Each level takes a '.', so capping the dots bounds the depth; a
// scene, comments and paths included, has a few hundred.
void checkDotCount(std::string_view text, const std::string& source) {
  constexpr std::size_t kMaxDots = 10000;
  std::size_t dots = 0;
  Line line = 1;
  for (const char c : text) {
    line += c == '\n';
    if (c == '.' && ++dots > kMaxDots)
      throw Error(fmt::format("{}:{}: TOML syntax: more than {} dots; keys may nest too deep to parse safely", source,
                              line, kMaxDots));
  }
}

}  // namespace

[[noreturn]] void failAt(const Context& ctx, Line line, std::string_view key, std::string_view what) {
  throw Error(fmt::format("{}:{}: {}: {}", ctx.source, line, key, what));
}

std::string printable(std::string_view text) {
  constexpr std::size_t kMax = 400;
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < kMax; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x20 || c == 0x7f)
      out += fmt::format("\\x{:02x}", c);
    else
      out += static_cast<char>(c);
  }
  if (text.size() > kMax) out += "...";
  return out;
}

std::string_view typeName(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a float";
    case toml::node_type::boolean:
      return "a boolean";
    case toml::node_type::date:
      return "a date";
    case toml::node_type::time:
      return "a time";
    case toml::node_type::date_time:
      return "a date-time";
    case toml::node_type::none:
      break;
  }
  return "nothing";
}

bool earlier(const toml::source_position& a, const toml::source_position& b) {
  return a.line != b.line ? a.line < b.line : a.column < b.column;
}

// Within 2 edits and fewer than the key is long: any two-letter key is 2 edits from any other.
std::optional<std::string_view> closest(std::string_view key, const Keys& known) {
  std::optional<std::string_view> best;
  std::size_t bestDistance = std::min<std::size_t>(3, key.size());
  for (std::string_view k : known)
    if (const std::size_t d = editDistance(key, k); d < bestDistance) {
      best = k;
      bestDistance = d;
    }
  return best;
}

bool contains(const Keys& keys, std::string_view key) { return std::find(keys.begin(), keys.end(), key) != keys.end(); }

Keys concat(const Keys& a, const Keys& b) {
  Keys all = a;
  all.insert(all.end(), b.begin(), b.end());
  return all;
}

// toml++ reports syntax errors by exception or by result, as it was built; both end in a vrd::Error.
toml::table parseToml(std::string_view text, const std::string& source) {
  checkDotCount(text, source);
#if TOML_EXCEPTIONS
  try {
    return toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    syntaxError(source, e);
  }
#else
  toml::parse_result result = toml::parse(text, source);
  if (!result) syntaxError(source, result.error());
  return std::move(result).table();
#endif
}

std::string readText(const std::filesystem::path& path) {
  const auto cannotRead = [&](std::string_view why) {
    return Error(fmt::format("{}: cannot read: {}", path.string(), why));
  };
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (!fs::exists(status)) throw cannotRead(std::strerror(ENOENT));
  if (!fs::is_regular_file(status)) throw cannotRead("not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw cannotRead(std::strerror(errno));
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (in.bad()) throw cannotRead("read failed");
  return text;
}

}  // namespace vrd::schema
