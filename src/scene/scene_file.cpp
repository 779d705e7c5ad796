// Scene files (docs/scenes.md): toml++ reads the TOML, this file checks it against the schema and
// fills a SceneSpec. People write these files by hand, so every message names the file, the line
// and the dotted key of the problem, and unknown keys are errors rather than silently ignored.
#include "vrdeform/scene/scene_file.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "vrdeform/error.h"

namespace vrd {
namespace {

// Scene files' defaults where the library keeps the paper's: 8 substeps (at the paper's 1 a soft
// body settling under gravity loses several percent of its volume, and more); fingertips with
// skin's friction (frictionless, a round body rolls away under the finger: docs/haptics.md); and
// soft tissue (the liver's) for a soft body whose material gives neither moduli nor compliances.
constexpr int kSceneSubsteps = 8;
constexpr FingertipFriction kSkin{0.8f, 0.6f};
constexpr ElasticModuli kSoftTissue{3.0e4f, 0.45f, 1060.0f, 0.005f};

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

[[noreturn]] void failAt(const Context& ctx, Line line, std::string_view key, std::string_view what) {
  throw Error(fmt::format("{}:{}: {}: {}", ctx.source, line, key, what));
}

// User text in a message: control bytes as \xNN and long text cut, so the message stays one line.
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

// The known key a typo most likely meant: within 2 edits, and fewer edits than the key is long
// (any two-letter key is 2 edits from any other).
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

// Rotation about x, then y, then z, in degrees: the order of BodySpec::rotationDeg.
Mat3 rotationFromDegrees(const Vec3& degrees) {
  const Vec3 r = degrees * float(std::numbers::pi / 180.0);
  return (Eigen::AngleAxisf(r.z(), Vec3::UnitZ()) * Eigen::AngleAxisf(r.y(), Vec3::UnitY()) *
          Eigen::AngleAxisf(r.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

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

SolverSettings readSolver(const Table& t) {
  t.allowOnly({"rate", "dt", "substeps", "iterations", "gravity", "linear_damping", "simd", "threads",
               "fuse_strain_volume", "measure_residuals", "tolerance", "warm_start"});
  t.exclusive("rate", "dt");
  SolverSettings s;
  s.substeps = kSceneSubsteps;
  if (std::optional<Field> f = t.get("rate")) s.timeStep = 1.0 / double(f->integer(1, 100000));
  t.readNumber("dt", s.timeStep, kPositive);
  t.readInt("substeps", s.substeps, 1, 1000);
  t.readInt("iterations", s.iterations, 1, 1000);
  t.readVec3("gravity", s.gravity);
  t.readNumber("linear_damping", s.linearDamping, kNonNegative);
  bool simd = true;
  t.readBool("simd", simd);
  s.simd = simd ? SimdLevel::Best : SimdLevel::Off;
  if (std::optional<Field> f = t.get("threads")) {
    if (f->isString() && f->string() != "auto")
      f->fail(fmt::format("expected an integer or \"auto\", got '{}'", printable(f->string())));
    s.threads = f->isString() ? SolverSettings::kAutoThreads : int(f->integer(1, 256));
  }
  t.readBool("fuse_strain_volume", s.fuseStrainVolume);
  s.measureResiduals = true;  // the scene default: runs and the viewer show how converged each step is
  t.readBool("measure_residuals", s.measureResiduals);
  t.readNumber("tolerance", s.tolerance, kNonNegative);
  t.readBool("warm_start", s.warmStart);
  validateAt(t, "solver", [&] { validateSolverSettings(s); });
  return s;
}

void readModuli(const Table& t, BodyKind kind, Material& m) {
  if (!t.has("youngs") && !t.has("poisson")) {
    if (t.has("rayleigh_damping")) t.fail("rayleigh_damping", "needs youngs, poisson and density");
    return;
  }
  for (std::string_view key : {"youngs", "poisson", "density"})
    if (!t.has(key)) t.fail(key, "missing (youngs, poisson and density go together)");
  if (kind == BodyKind::Cloth) t.fail("youngs", "a cloth takes compliance and damping, not moduli");
  if (t.has("particle_mass")) t.fail("particle_mass", "cannot go with moduli: the density gives the masses");
  ElasticModuli e{t.require("youngs").number<float>(kPositive),
                  t.require("poisson").number<float>(Range{0, 0.5, false, true}),
                  t.require("density").number<float>(kPositive)};
  t.readNumber("rayleigh_damping", e.rayleighDamping, kNonNegative);
  m.elastic = e;
}

// Masses: lumped from the density (soft) or areal density (cloth), or a fixed mass per particle.
void readMass(const Table& t, BodyKind kind, Material& m) {
  const bool cloth = kind == BodyKind::Cloth;
  if (cloth && t.has("density")) t.fail("density", "a cloth's masses come from areal_density (kg/m^2)");
  if (!cloth && t.has("areal_density")) t.fail("areal_density", "a soft body's masses come from density (kg/m^3)");
  if (t.has("particle_mass"))
    for (std::string_view key : {"density", "areal_density"})
      if (t.has(key)) t.fail("particle_mass", fmt::format("cannot go with {}: one of them gives the masses", key));
  t.readNumber("density", m.density, kPositive);
  t.readNumber("areal_density", m.arealDensity, kPositive);
  if (std::optional<Field> f = t.get("particle_mass")) m.particleMass = f->number<float>(kPositive);
}

// A soft body whose material table gives neither moduli nor the paper's compliance form: soft
// tissue (as the liver's), so that a scene of a mesh alone weighs and deforms as a body would.
bool takesSoftTissue(const Table& t, BodyKind kind) {
  if (kind != BodyKind::Soft) return false;
  for (std::string_view key : {"youngs", "poisson", "compliance", "damping", "particle_mass", "distance", "volume",
                               "strain_stretch", "strain_shear", "shape_matching", "bending"})
    if (t.has(key)) return false;
  return true;
}

Material readMaterial(const Table& t, BodyKind kind) {
  static constexpr Option<ConstraintMaterial Material::*> kTypes[] = {{"distance", &Material::distance},
                                                                      {"volume", &Material::volume},
                                                                      {"strain_stretch", &Material::strainStretch},
                                                                      {"strain_shear", &Material::strainShear},
                                                                      {"shape_matching", &Material::shapeMatching},
                                                                      {"bending", &Material::bending}};
  Keys keys = {"youngs",     "poisson", "density",       "areal_density",  "rayleigh_damping",
               "compliance", "damping", "particle_mass", "particle_radius"};
  for (const auto& type : kTypes) keys.push_back(type.name);
  t.allowOnly(keys);

  Material m;
  if (takesSoftTissue(t, kind)) {
    m.elastic = kSoftTissue;
    t.readNumber("density", m.elastic->density, kPositive);
    t.readNumber("rayleigh_damping", m.elastic->rayleighDamping, kNonNegative);
  } else {
    readModuli(t, kind, m);
  }
  readMass(t, kind, m);
  // The blanket values first, so that a type's own table overrides them.
  if (std::optional<Field> f = t.get("compliance"))
    for (const auto& type : kTypes) (m.*type.value).compliance = f->number<float>(kNonNegative);
  if (std::optional<Field> f = t.get("damping"))
    for (const auto& type : kTypes) (m.*type.value).damping = f->number<float>(kNonNegative);
  for (const auto& type : kTypes) {
    const Table sub = t.table(type.name);
    sub.allowOnly({"compliance", "damping"});
    sub.readNumber("compliance", (m.*type.value).compliance, kNonNegative);
    sub.readNumber("damping", (m.*type.value).damping, kNonNegative);
  }
  t.readNumber("particle_radius", m.particleRadius, kNonNegative);
  return m;
}

ConstraintSet readConstraints(const Field& f) {
  static constexpr Option<bool ConstraintSet::*> kNames[] = {{"edges", &ConstraintSet::edges},
                                                             {"volume", &ConstraintSet::volume},
                                                             {"strain", &ConstraintSet::strain},
                                                             {"shape_matching", &ConstraintSet::shapeMatching}};
  const std::vector<Field> names = f.elements("an array of strings");
  if (names.empty()) f.fail("must list at least one of: edges, volume, strain, shape_matching");
  ConstraintSet set{false, false, false, false};
  for (const Field& name : names) set.*name.choose(kNames) = true;
  return set;
}

std::vector<std::string> readPins(const Field& f) {
  static constexpr Option<std::string_view> kSides[] = {{"-x", "-x"}, {"+x", "+x"}, {"-y", "-y"},
                                                        {"+y", "+y"}, {"-z", "-z"}, {"+z", "+z"}};
  std::vector<std::string> pins;
  for (const Field& side : f.elements("an array of strings")) pins.emplace_back(side.choose(kSides));
  return pins;
}

BodyContactSettings readBodyContact(const Table& t) {
  t.allowOnly({"bodies", "self", "thickness", "static_friction", "dynamic_friction", "compliance"});
  BodyContactSettings c;
  t.readBool("bodies", c.bodies);
  t.readBool("self", c.self);
  t.readNumber("thickness", c.thickness, kNonNegative);
  t.readNumber("static_friction", c.staticFriction, kNonNegative);
  t.readNumber("dynamic_friction", c.dynamicFriction, kNonNegative);
  t.readNumber("compliance", c.compliance, kNonNegative);
  return c;
}

BodySpec readBody(const Table& t, std::size_t number) {
  static constexpr Option<BodyKind> kKinds[] = {{"soft", BodyKind::Soft}, {"cloth", BodyKind::Cloth}};
  static constexpr Option<Placement> kPlacements[] = {{"ground", Placement::Ground}, {"as_is", Placement::AsIs}};
  static constexpr Option<Mesher> kMeshers[] = {{"builtin", Mesher::Builtin}, {"tetgen", Mesher::TetGen}};
  static const Keys kCommon = {"name",      "kind",  "mesh",     "scale", "rotation", "position",
                               "placement", "force", "material", "on",    "contact"};
  static const Keys kSoftOnly = {"render_mesh", "mesher", "tets", "max_volume", "constraints"};
  static const Keys kClothOnly = {"pin", "pin_tolerance"};

  BodySpec body;
  t.readChoice("kind", body.kind, kKinds);
  const bool soft = body.kind == BodyKind::Soft;
  t.allowOnly(concat(kCommon, soft ? kSoftOnly : kClothOnly), soft ? kClothOnly : kSoftOnly,
              soft ? "a soft body" : "a cloth");

  body.name = fmt::format("body{}", number);
  if (std::optional<Field> f = t.get("name")) body.name = f->name();
  body.mesh = t.require("mesh").file();
  if (std::optional<Field> f = t.get("render_mesh")) body.renderMesh = f->file();
  t.readNumber("scale", body.scale, kPositive);
  Vec3 rotation = Vec3::Zero();
  t.readVec3("rotation", rotation);
  body.rotationDeg = {rotation.x(), rotation.y(), rotation.z()};
  t.readVec3("position", body.position);
  t.readChoice("placement", body.placement, kPlacements);
  t.readChoice("mesher", body.mesher.mesher, kMeshers);
  t.exclusive("tets", "max_volume");  // a tet count search picks its own volume bound
  if (std::optional<Field> f = t.get("tets")) body.mesher.targetTets = std::size_t(f->integer(6, 2000000));
  t.readNumber("max_volume", body.mesher.maxVolume, kPositive);
  if (std::optional<Field> f = t.get("constraints")) body.constraints = readConstraints(*f);
  if (std::optional<Field> f = t.get("pin")) body.pin = readPins(*f);
  t.readNumber("pin_tolerance", body.pinTolerance, kNonNegative);
  t.readVec3("force", body.force);
  body.material = readMaterial(t.table("material"), body.kind);
  if (std::optional<Field> f = t.get("on")) body.on = f->name();
  body.contact = readBodyContact(t.table("contact"));
  return body;
}

Collider readCollider(const Table& t) {
  static constexpr Option<ColliderShape> kShapes[] = {
      {"plane", ColliderShape::Plane}, {"sphere", ColliderShape::Sphere}, {"box", ColliderShape::Box}};
  static const Keys kCommon = {"type", "static_friction", "dynamic_friction", "compliance"};
  static const Keys kPlane = {"normal", "point"}, kSphere = {"center", "radius"},
                    kBox = {"center", "half_extents", "rotation"};

  const Field type = t.require("type");
  const ColliderShape shape = type.choose(kShapes);
  const Keys& own = shape == ColliderShape::Plane ? kPlane : shape == ColliderShape::Sphere ? kSphere : kBox;
  Keys others;
  for (std::string_view key : concat(concat(kPlane, kSphere), kBox))
    if (!contains(own, key)) others.push_back(key);
  t.allowOnly(concat(kCommon, own), others, fmt::format("a {} collider", type.string()));

  Collider c;
  Vec3 center = Vec3::Zero();
  t.readVec3("center", center);
  switch (shape) {
    case ColliderShape::Plane: {
      Vec3 normal = Vec3::UnitY(), point = Vec3::Zero();
      t.readVec3("normal", normal);
      if (!(normal.norm() > 0.0f)) t.fail("normal", "must not be zero");
      t.readVec3("point", point);
      c = Collider::plane(normal, point);
      break;
    }
    case ColliderShape::Sphere:
      c = Collider::sphere(center, t.require("radius").number<float>(kPositive));
      break;
    case ColliderShape::Box: {
      const Vec3 halfExtents = t.require("half_extents").vec3(kPositive);
      Vec3 rotation = Vec3::Zero();
      t.readVec3("rotation", rotation);
      c = Collider::box(center, halfExtents, rotationFromDegrees(rotation));
      break;
    }
  }
  t.readNumber("static_friction", c.staticFriction, kNonNegative);
  t.readNumber("dynamic_friction", c.dynamicFriction, kNonNegative);
  t.readNumber("compliance", c.compliance, kNonNegative);
  validateAt(t, "collider", [&] { validateCollider(c); });
  return c;
}

ActionSpec readAction(const Table& t, const HandRigSettings& rig, std::string_view model,
                      const std::vector<BodySpec>& bodies) {
  static constexpr Option<ActionKind> kKinds[] = {{"poke", ActionKind::Poke}, {"grasp", ActionKind::Grasp}};
  static constexpr Option<Finger> kFingers[] = {{"thumb", Finger::Thumb},
                                                {"index", Finger::Index},
                                                {"middle", Finger::Middle},
                                                {"ring", Finger::Ring},
                                                {"little", Finger::Little}};
  static const Keys kCommon = {"type", "body", "finger", "start", "approach", "hold", "release", "depth", "offset"};
  static const Keys kGrasp = {"width", "lift"};
  static const Keys kPoke = {"profile"};
  static constexpr Option<PokeProfile> kProfiles[] = {{"minimum_jerk", PokeProfile::MinimumJerk},
                                                      {"linear", PokeProfile::Linear}};

  ActionSpec a;
  HandAction& h = a.action;
  h.kind = t.require("type").choose(kKinds);
  const bool poke = h.kind == ActionKind::Poke;
  t.allowOnly(concat(kCommon, poke ? kPoke : kGrasp), poke ? kGrasp : kPoke, poke ? "a poke" : "a grasp");

  if (std::optional<Field> f = t.get("body")) {
    a.body = f->string();
    std::vector<std::string_view> names;
    for (const BodySpec& b : bodies) names.push_back(b.name);
    if (!contains(names, a.body))
      f->fail(fmt::format("no body named '{}' (the bodies: {})", printable(a.body), fmt::join(names, ", ")));
  }
  if (std::optional<Field> f = t.get("finger")) {
    h.finger = f->choose(kFingers);
    if (!poke && h.finger == Finger::Thumb)
      f->fail("a grasp pairs the thumb with another finger; name that finger (index, middle, ring or little)");
    if (!rig.fingers[int(h.finger)])
      f->fail(fmt::format("the {} hand has no {} fingertip (model = \"pro\" has all five)", model, f->string()));
  }
  t.readNumber("start", h.start, kNonNegative);
  t.readNumber("approach", h.approach, kPositive);
  t.readNumber("hold", h.hold, kNonNegative);
  t.readNumber("release", h.release, kPositive);
  t.readNumber("depth", h.depth, kNonNegative);
  t.readNumber("width", h.width, kNonNegative);
  t.readNumber("lift", h.lift, kNonNegative);
  t.readVec3("offset", a.offset);
  t.readChoice("profile", h.profile, kProfiles);
  return a;
}

HandSpec readHand(const Table& t, const std::vector<BodySpec>& bodies) {
  static constexpr Option<std::string_view> kModels[] = {{"g1", "g1"}, {"pro", "pro"}};
  static constexpr Option<FingertipContactMode> kContacts[] = {{"particles", FingertipContactMode::Particles},
                                                               {"triangles", FingertipContactMode::Triangles}};
  static constexpr Option<std::optional<GraspMode>> kGrasps[] = {
      {"local", GraspMode::Local}, {"paper", GraspMode::Paper}, {"off", std::nullopt}};
  t.allowOnly({"enabled", "model", "contact", "fingertip_radius", "compliance", "static_friction", "dynamic_friction",
               "grasp", "release_opening", "closing_speed", "hold_reach", "hold_compliance", "script", "action"});

  HandSpec hand;
  t.readBool("enabled", hand.enabled);
  std::string_view model = "g1";
  t.readChoice("model", model, kModels);
  hand.rig = model == "pro" ? HandRigSettings::pro() : HandRigSettings::g1();
  hand.rig.contact = FingertipContactMode::Triangles;  // the scene defaults, unlike HandRigSettings'
  hand.rig.friction = kSkin;
  t.readChoice("contact", hand.rig.contact, kContacts);
  t.readNumber("fingertip_radius", hand.rig.geometry.fingertipRadius, kPositive);
  t.readNumber("compliance", hand.rig.compliance, kNonNegative);
  t.readNumber("static_friction", hand.rig.friction.staticFriction, kNonNegative);
  t.readNumber("dynamic_friction", hand.rig.friction.dynamicFriction, kNonNegative);

  std::optional<GraspMode> grasp = hand.grasp.mode;
  t.readChoice("grasp", grasp, kGrasps);
  hand.grasp.enabled = grasp.has_value();
  hand.grasp.mode = grasp.value_or(hand.grasp.mode);
  t.readNumber("release_opening", hand.grasp.releaseOpening, kNonNegative);
  t.readNumber("closing_speed", hand.grasp.closingSpeed, kNonNegative);
  t.readNumber("hold_reach", hand.grasp.holdReach, kNonNegative);
  t.readNumber("hold_compliance", hand.grasp.holdCompliance, kNonNegative);
  validateAt(t, "grasp", [&] { validateGraspSettings(hand.grasp); });

  if (std::optional<Field> f = t.get("script")) hand.script = f->file();
  for (const Table& action : t.tables("action")) hand.actions.push_back(readAction(action, hand.rig, model, bodies));
  if (!hand.script.empty() && !hand.actions.empty())
    t.fail("script", "a script replaces the [[hand.action]] list; give one or the other");
  return hand;
}

HapticsSpec readHaptics(const Table& t) {
  t.allowOnly({"calibrate", "alpha", "beta_contact", "beta_volume", "beta_strain", "epsilon", "tau_contact",
               "tau_finger_contact", "tau_volume", "tau_strain", "max_change_per_ms", "baseline_contact_force",
               "baseline_stiffness"});
  HapticsSpec h;
  HapticSignalSettings& s = h.settings.signal;
  t.readBool("calibrate", h.calibrate);
  t.readNumber("alpha", s.alphaT, Range{0, 1, true, false});
  t.readNumber("beta_contact", s.betaContact, kUnit);
  // beta_v + beta_s = 1 (eq. 42), so one of them gives the other.
  t.readNumber("beta_volume", s.betaVolume, kUnit);
  t.readNumber("beta_strain", s.betaStrain, kUnit);
  if (t.has("beta_volume") && !t.has("beta_strain")) s.betaStrain = 1.0f - s.betaVolume;
  if (t.has("beta_strain") && !t.has("beta_volume")) s.betaVolume = 1.0f - s.betaStrain;
  if (std::abs(s.betaVolume + s.betaStrain - 1.0f) > 1e-4f)
    t.fail("beta_strain", fmt::format("beta_volume + beta_strain must be 1, got {}", s.betaVolume + s.betaStrain));
  t.readNumber("epsilon", s.epsilon, kNonNegative);
  t.readNumber("tau_contact", s.tauContact, kPositive);
  t.readNumber("tau_finger_contact", s.tauFingerContact, kPositive);
  t.readNumber("tau_volume", s.tauVolume, kPositive);
  t.readNumber("tau_strain", s.tauStrain, kPositive);
  if (std::optional<Field> f = t.get("max_change_per_ms")) {
    if (f->isString() && f->string() != "inf")
      f->fail(fmt::format("expected a number or \"inf\", got '{}'", printable(f->string())));
    const bool unlimited = f->isString() || f->real() == kInf;
    h.settings.maxChangePerMs = unlimited ? std::numeric_limits<float>::infinity() : f->number<float>(kPositive);
  }
  t.readNumber("baseline_contact_force", h.settings.baseline.contactForce, kUnit);
  t.readNumber("baseline_stiffness", h.settings.baseline.stiffness, kNonNegative);
  validateAt(t, "haptics", [&] { validateHapticSettings(h.settings); });
  return h;
}

OutputSpec readOutput(const Table& t) {
  t.allowOnly({"mesh_every", "plots"});
  OutputSpec out;
  t.readNumber("mesh_every", out.meshEvery, kNonNegative);
  t.readBool("plots", out.plots);
  return out;
}

bool hasBody(const std::vector<BodySpec>& bodies, std::string_view name) {
  return std::any_of(bodies.begin(), bodies.end(), [&](const BodySpec& b) { return b.name == name; });
}

SceneSpec readScene(const Table& root, std::string_view sourceName) {
  root.allowOnly({"format", "name", "description", "settle", "seconds", "wind", "ground", "solver", "body", "collider",
                  "no_contact", "hand", "haptics", "output"});
  if (std::optional<Field> f = root.get("format"); f && f->integer() != 1)
    f->fail(fmt::format("this vrdeform reads format 1, got {}", f->integer()));

  SceneSpec scene;
  scene.name = fs::path(sourceName).stem().string();
  if (std::optional<Field> f = root.get("name")) scene.name = f->name();
  root.readString("description", scene.description);
  // Until the bodies are at rest (at most kSettleToRestMost s) unless the file says how long.
  scene.settleToRest = !root.has("settle");
  scene.settle = scene.settleToRest ? SceneSpec::kSettleToRestMost : scene.settle;
  root.readNumber("settle", scene.settle, kNonNegative);
  root.readNumber("seconds", scene.seconds, kPositive);
  root.readVec3("wind", scene.wind);
  scene.solver = readSolver(root.table("solver"));

  const std::vector<Table> bodies = root.tables("body");
  if (!root.has("body")) root.fail("body", "missing (a scene needs at least one [[body]])");
  if (bodies.empty()) root.fail("body", "is empty (a scene needs at least one [[body]])");
  for (const Table& t : bodies) {
    BodySpec body = readBody(t, scene.bodies.size() + 1);
    for (std::size_t i = 0; i < scene.bodies.size(); ++i)
      if (scene.bodies[i].name == body.name)
        t.fail("name", fmt::format("'{}' is also the name of body[{}]", printable(body.name), i + 1));
    if (!body.on.empty() && !hasBody(scene.bodies, body.on))
      t.fail("on", fmt::format("no body '{}' before this one", printable(body.on)));
    scene.bodies.push_back(std::move(body));
  }
  for (const Table& t : root.tables("no_contact")) {
    t.allowOnly({"bodies"});
    const std::vector<Field> names = t.require("bodies").elements("an array of two body names");
    if (names.size() != 2) t.fail("bodies", fmt::format("needs two body names, got {}", names.size()));
    std::array<std::string, 2> pair{names[0].name(), names[1].name()};
    for (const std::string& name : pair)
      if (!hasBody(scene.bodies, name)) t.fail("bodies", fmt::format("no body '{}'", printable(name)));
    if (pair[0] == pair[1]) t.fail("bodies", "names one body twice (its self-contact is [body.contact] self)");
    scene.noContact.push_back(std::move(pair));
  }
  for (const Table& t : root.tables("collider")) scene.colliders.push_back(readCollider(t));
  bool ground = true;  // a scene of a mesh alone stands on something
  root.readBool("ground", ground);
  if (ground && scene.colliders.empty()) scene.colliders.push_back(Collider::plane(Vec3::UnitY()));
  scene.hand = readHand(root.table("hand"), scene.bodies);
  scene.haptics = readHaptics(root.table("haptics"));
  scene.output = readOutput(root.table("output"));
  return scene;
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

std::string readText(const fs::path& path) {
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

}  // namespace

SceneSpec parseScene(std::string_view text, std::string_view sourceName, const fs::path& baseDir) {
  const Context ctx{std::string(sourceName), baseDir};
  const toml::table root = parseToml(text, ctx.source);
  SceneSpec scene = readScene(Table(ctx, root, "", 1), sourceName);
  scene.source = sourceName;
  return scene;
}

SceneSpec loadScene(const fs::path& path) {
  const std::string text = readText(path);
  std::error_code error;
  fs::path absolute = fs::absolute(path, error);
  if (error) absolute = path;
  absolute = absolute.lexically_normal();
  SceneSpec scene = parseScene(text, path.string(), absolute.parent_path());
  scene.source = absolute.string();
  return scene;
}

SceneSpec sceneOfMesh(const fs::path& mesh) {
  const toml::table root{{"body", toml::array{toml::table{{"mesh", mesh.string()}}}}};
  std::error_code error;
  const Context ctx{mesh.string(), fs::current_path(error)};
  SceneSpec scene = readScene(Table(ctx, root, "", 1), mesh.string());
  scene.source = scene.bodies.front().mesh;
  return scene;
}

}  // namespace vrd
