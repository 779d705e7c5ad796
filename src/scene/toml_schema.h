#pragma once
// Reading hand-written TOML files against a schema (scene files, study files): every value with its
// dotted key and line, so that each message names the file, the line and the key of the problem,
// and unknown keys are errors with the likely intended key. Private to the scene layer.

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "vrdeform/error.h"
#include "vrdeform/math/types.h"

namespace vrd::schema {

namespace fs = std::filesystem;
using Line = toml::source_index;
using Keys = std::vector<std::string_view>;

constexpr double kInf = std::numeric_limits<double>::infinity();

/// The values a number may take; it also words the message for one outside them.
struct Range {
  double lo = -kInf, hi = kInf;
  bool loOpen = false, hiOpen = false;

  bool contains(double v) const { return (loOpen ? v > lo : v >= lo) && (hiOpen ? v < hi : v <= hi); }
  std::string describe() const {
    if (hi == kInf)
      return lo == 0 && loOpen ? "must be positive" : fmt::format("must be {} {}", loOpen ? ">" : ">=", lo);
    return fmt::format("must be in {}{}, {}{}", loOpen ? '(' : '[', lo, hi, hiOpen ? ')' : ']');
  }
};
constexpr Range kAnyValue{};
constexpr Range kPositive{0, kInf, true};
constexpr Range kNonNegative{0, kInf};
constexpr Range kUnit{0, 1};

/// A name the file may use for a value of type T.
template <typename T>
struct Option {
  std::string_view name;
  T value;
};

struct Context {
  std::string source;  // the file's name in messages
  fs::path baseDir;    // relative paths start here
};

[[noreturn]] void failAt(const Context& ctx, Line line, std::string_view key, std::string_view what);
/// User text in a message: control bytes as \xNN and long text cut, so the message stays one line.
std::string printable(std::string_view text);
std::string_view typeName(const toml::node& node);
bool earlier(const toml::source_position& a, const toml::source_position& b);
/// The known key a typo most likely meant: within 2 edits, and fewer edits than the key is long.
std::optional<std::string_view> closest(std::string_view key, const Keys& known);
bool contains(const Keys& keys, std::string_view key);
Keys concat(const Keys& a, const Keys& b);
/// The file's text parsed; a syntax error (or keys nested too deep to parse safely) as a vrd::Error
/// with the file and line.
toml::table parseToml(std::string_view text, const std::string& source);
/// A whole file's text; a vrd::Error saying why it cannot be read.
std::string readText(const std::filesystem::path& path);

/// One value of the file with its dotted key, read as the type the schema wants.
class Field {
 public:
  Field(const Context& ctx, const toml::node& node, std::string key, Line fallbackLine)
      : ctx_(&ctx), node_(&node), key_(std::move(key)) {
    line_ = node.source().begin.line ? node.source().begin.line : fallbackLine;
  }

  Line line() const { return line_; }
  const std::string& key() const { return key_; }
  const toml::source_position& position() const { return node_->source().begin; }

  [[noreturn]] void fail(std::string_view what) const { failAt(*ctx_, line_, key_, what); }
  [[noreturn]] void expected(std::string_view what) const {
    fail(fmt::format("expected {}, got {}", what, typeName(*node_)));
  }

  bool isString() const { return node_->is_string(); }

  /// Any number, integers included; may be nan or infinite.
  double real() const {
    if (const auto* i = node_->as_integer()) return double(i->get());
    if (const auto* f = node_->as_floating_point()) return f->get();
    expected("a number");
  }

  /// A finite number in `range` that fits T (float or double).
  template <typename T>
  T number(const Range& range = kAnyValue) const {
    const double v = real();
    if (!std::isfinite(v)) fail(fmt::format("must be a finite number, got {}", v));
    if (std::abs(v) > double(std::numeric_limits<T>::max())) fail(fmt::format("is out of range, got {}", v));
    const T value = static_cast<T>(v);
    if (!range.contains(value)) fail(fmt::format("{}, got {}", range.describe(), value));
    return value;
  }

  std::int64_t integer(std::int64_t lo = std::numeric_limits<std::int64_t>::min(),
                       std::int64_t hi = std::numeric_limits<std::int64_t>::max()) const {
    const auto* i = node_->as_integer();
    if (!i) expected("an integer");
    if (i->get() < lo || i->get() > hi) fail(fmt::format("must be in {}..{}, got {}", lo, hi, i->get()));
    return i->get();
  }

  bool boolean() const {
    if (const auto* b = node_->as_boolean()) return b->get();
    expected("a boolean (true or false)");
  }

  std::string string() const {
    if (const auto* s = node_->as_string()) return s->get();
    expected("a string");
  }

  const toml::table& table() const {
    if (const auto* t = node_->as_table()) return *t;
    expected("a table");
  }

  std::string name() const {
    std::string s = string();
    if (s.empty()) fail("must not be empty");
    return s;
  }

  template <typename T, std::size_t N>
  T choose(const Option<T> (&options)[N]) const {
    const std::string s = string();
    for (const Option<T>& o : options)
      if (o.name == s) return o.value;
    std::vector<std::string_view> names;
    for (const Option<T>& o : options) names.push_back(o.name);
    fail(fmt::format("unknown value '{}' (expected one of: {})", printable(s), fmt::join(names, ", ")));
  }

  /// The elements of an array, each with the key `key[i]` (from 1).
  std::vector<Field> elements(std::string_view what) const {
    const toml::array* array = node_->as_array();
    if (!array) expected(what);
    std::vector<Field> out;
    for (std::size_t i = 0; i < array->size(); ++i)
      out.emplace_back(*ctx_, *array->get(i), fmt::format("{}[{}]", key_, i + 1), line_);
    return out;
  }

  Vec3 vec3(const Range& range = kAnyValue) const {
    const std::vector<Field> e = elements("an array of 3 numbers");
    if (e.size() != 3) fail(fmt::format("expected an array of 3 numbers, got {} of them", e.size()));
    return {e[0].number<float>(range), e[1].number<float>(range), e[2].number<float>(range)};
  }

  /// An existing regular file, absolute and lexically normal; a relative name starts at the base folder.
  std::string file() const {
    const std::string text = name();
    if (text.find('\0') != std::string::npos) fail("contains a NUL character");
    std::error_code error;
    fs::path path = fs::path(text).is_relative() ? ctx_->baseDir / text : fs::path(text);
    if (fs::path absolute = fs::absolute(path, error); !error) path = absolute;
    path = path.lexically_normal();
    const fs::file_status status = fs::status(path, error);
    if (!fs::exists(status)) fail(fmt::format("no such file '{}'", printable(path.string())));
    if (!fs::is_regular_file(status)) fail(fmt::format("'{}' is not a regular file", printable(path.string())));
    return path.string();
  }

 private:
  const Context* ctx_;
  const toml::node* node_;
  std::string key_;
  Line line_;
};

/// A table of the file with its dotted path (`body[1].material`) and the line of its header.
class Table {
 public:
  Table(const Context& ctx, const toml::table& table, std::string path, Line fallbackLine)
      : ctx_(&ctx), table_(&table), path_(std::move(path)) {
    line_ = table.source().begin.line ? table.source().begin.line : fallbackLine;
  }

  Line line() const { return line_; }
  std::string keyOf(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }
  bool has(std::string_view key) const { return table_->contains(key); }

  std::optional<Field> get(std::string_view key) const {
    const toml::node* node = table_->get(key);
    if (!node) return std::nullopt;
    return Field(*ctx_, *node, keyOf(key), line_);
  }

  Field require(std::string_view key) const {
    if (std::optional<Field> f = get(key)) return *f;
    failAt(*ctx_, line_, keyOf(key), "missing");
  }

  /// Fails at the key's line, or at the table's header when the key is absent.
  [[noreturn]] void fail(std::string_view key, std::string_view what) const {
    if (std::optional<Field> f = get(key)) f->fail(what);
    failAt(*ctx_, line_, keyOf(key), what);
  }
  [[noreturn]] void failHere(std::string_view what) const { failAt(*ctx_, line_, path_, what); }

  /// Rejects the first key in the file's order that is not in `allowed`: one in `misplaced` as not
  /// applying to `misplacedFor` (a key of another kind of body, collider or action), any other as
  /// unknown, with the likely intended key or the known ones.
  void allowOnly(const Keys& allowed, const Keys& misplaced = {}, std::string_view misplacedFor = {}) const {
    const toml::key* first = nullptr;
    for (auto&& entry : *table_)
      if (!contains(allowed, entry.first.str()) &&
          (!first || earlier(entry.first.source().begin, first->source().begin)))
        first = &entry.first;
    if (!first) return;
    const std::string_view key = first->str();
    const Line line = first->source().begin.line ? first->source().begin.line : line_;
    if (contains(misplaced, key)) failAt(*ctx_, line, keyOf(key), fmt::format("does not apply to {}", misplacedFor));
    if (const std::optional<std::string_view> guess = closest(key, allowed))
      failAt(*ctx_, line, keyOf(printable(key)), fmt::format("unknown key (did you mean '{}'?)", *guess));
    failAt(*ctx_, line, keyOf(printable(key)),
           fmt::format("unknown key (expected one of: {})", fmt::join(allowed, ", ")));
  }

  /// Fails at the later of two keys that may not both be given.
  void exclusive(std::string_view a, std::string_view b) const {
    const std::optional<Field> fa = get(a), fb = get(b);
    if (!fa || !fb) return;
    (earlier(fa->position(), fb->position()) ? *fb : *fa).fail(fmt::format("give either {} or {}, not both", a, b));
  }

  /// The sub-table `key`; an empty one when absent, so that its defaults and checks still apply.
  Table table(std::string_view key) const {
    static const toml::table kEmpty;
    const std::optional<Field> field = get(key);
    if (!field) return Table(*ctx_, kEmpty, keyOf(key), line_);
    return Table(*ctx_, field->table(), keyOf(key), line_);
  }

  /// The array of tables `key` ([[key]]), each with the path `key[i]` (from 1); empty when absent.
  std::vector<Table> tables(std::string_view key) const {
    const std::optional<Field> field = get(key);
    if (!field) return {};
    std::vector<Table> out;
    for (const Field& element : field->elements(fmt::format("an array of tables ([[{}]])", keyOf(key))))
      out.emplace_back(*ctx_, element.table(), element.key(), element.line());
    return out;
  }

  // Shorthands: set `out` when the key is present, leave the default otherwise.
  template <typename T>
  void readNumber(std::string_view key, T& out, const Range& range = kAnyValue) const {
    if (std::optional<Field> f = get(key)) out = f->number<T>(range);
  }
  void readInt(std::string_view key, int& out, int lo, int hi) const {
    if (std::optional<Field> f = get(key)) out = int(f->integer(lo, hi));
  }
  void readBool(std::string_view key, bool& out) const {
    if (std::optional<Field> f = get(key)) out = f->boolean();
  }
  void readString(std::string_view key, std::string& out) const {
    if (std::optional<Field> f = get(key)) out = f->string();
  }
  void readVec3(std::string_view key, Vec3& out, const Range& range = kAnyValue) const {
    if (std::optional<Field> f = get(key)) out = f->vec3(range);
  }
  template <typename T, std::size_t N>
  void readChoice(std::string_view key, T& out, const Option<T> (&options)[N]) const {
    if (std::optional<Field> f = get(key)) out = f->choose(options);
  }

 private:
  const Context* ctx_;
  const toml::table* table_;
  std::string path_;
  Line line_;
};

// Runs a library validator and reports its vrd::Error at the table, without the validator's own
// "prefix: " when it repeats the table's name.
template <typename F>
void validateAt(const Table& t, std::string_view prefix, F&& validate) {
  try {
    validate();
  } catch (const Error& e) {
    std::string_view what = e.what();
    if (what.starts_with(prefix) && what.substr(prefix.size()).starts_with(": ")) what.remove_prefix(prefix.size() + 2);
    t.failHere(what);
  }
}

}  // namespace vrd::schema
