#include "io/ply_reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <optional>
#include <sstream>
#include <string_view>
#include <vector>

#include "io/binary.h"
#include "vrdeform/error.h"

namespace vrd {
namespace {

enum class Encoding { Ascii, LittleEndian, BigEndian };

std::optional<io::Scalar> scalarType(std::string_view name) {
  static constexpr std::pair<std::string_view, io::Scalar> kNames[] = {
      {"char", io::Scalar::Int8},      {"int8", io::Scalar::Int8},       {"uchar", io::Scalar::UInt8},
      {"uint8", io::Scalar::UInt8},    {"short", io::Scalar::Int16},     {"int16", io::Scalar::Int16},
      {"ushort", io::Scalar::UInt16},  {"uint16", io::Scalar::UInt16},   {"int", io::Scalar::Int32},
      {"int32", io::Scalar::Int32},    {"uint", io::Scalar::UInt32},     {"uint32", io::Scalar::UInt32},
      {"float", io::Scalar::Float32},  {"float32", io::Scalar::Float32}, {"double", io::Scalar::Float64},
      {"float64", io::Scalar::Float64}};
  for (const auto& [n, s] : kNames)
    if (n == name) return s;
  return std::nullopt;
}

struct Property {
  std::string name;
  io::Scalar type;
  std::optional<io::Scalar> listCount;  // set for list properties
  int axis = -1;                        // 0, 1, 2 for x, y, z
};

struct Element {
  std::string name;
  std::size_t count = 0;
  std::vector<Property> properties;
};

// Reads scalars one at a time from the data section, in either encoding.
class DataReader {
 public:
  DataReader(const std::string& name, const std::string& bytes, std::size_t pos, Encoding encoding)
      : name_(name), bytes_(bytes), pos_(pos), encoding_(encoding) {}

  double read(io::Scalar type) {
    if (encoding_ == Encoding::Ascii) return readText();
    if (bytes_.size() - pos_ < io::sizeOf(type))
      throw Error(fmt::format("{}: the file ends in the middle of its data (truncated?)", name_));
    const auto* p = reinterpret_cast<const unsigned char*>(bytes_.data() + pos_);
    pos_ += io::sizeOf(type);
    return io::loadScalar<double>(p, type, encoding_ == Encoding::BigEndian);
  }

 private:
  double readText() {
    while (pos_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
    if (pos_ == bytes_.size())
      throw Error(fmt::format("{}: the file ends in the middle of its data (truncated?)", name_));
    double value = 0;
    const auto [end, error] = std::from_chars(bytes_.data() + pos_, bytes_.data() + bytes_.size(), value);
    if (error != std::errc()) {
      const std::size_t line = 1 + std::count(bytes_.begin(), bytes_.begin() + pos_, '\n');
      throw Error(fmt::format("{}:{}: expected a number, found '{}'", name_, line, bytes_.substr(pos_, 12)));
    }
    pos_ = end - bytes_.data();
    return value;
  }

  const std::string& name_;
  const std::string& bytes_;
  std::size_t pos_;
  Encoding encoding_;
};

}  // namespace

TriMesh readPly(const std::filesystem::path& path, const std::string& bytes) {
  const std::string name = path.string();
  const std::size_t headerEnd = bytes.find("end_header");
  if (bytes.rfind("ply", 0) != 0) throw Error(fmt::format("{}: not a PLY file (it must start with 'ply')", name));
  if (headerEnd == std::string::npos)
    throw Error(fmt::format("{}: the PLY header has no end_header (truncated?)", name));
  std::size_t dataStart = bytes.find('\n', headerEnd);
  dataStart = dataStart == std::string::npos ? bytes.size() : dataStart + 1;

  std::istringstream header(bytes.substr(0, headerEnd));
  std::optional<Encoding> encoding;
  std::vector<Element> elements;
  std::string line;
  for (int lineNo = 1; std::getline(header, line); ++lineNo) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    auto fail = [&](const std::string& what) { return Error(fmt::format("{}:{}: {}", name, lineNo, what)); };
    if (keyword == "format") {
      std::string format, version;
      words >> format >> version;
      if (format == "ascii")
        encoding = Encoding::Ascii;
      else if (format == "binary_little_endian")
        encoding = Encoding::LittleEndian;
      else if (format == "binary_big_endian")
        encoding = Encoding::BigEndian;
      else
        throw fail(fmt::format("unknown PLY format '{}'", format));
    } else if (keyword == "element") {
      Element e;
      long long count = -1;
      words >> e.name >> count;
      if (!words || count < 0) throw fail("malformed element line");
      e.count = static_cast<std::size_t>(count);
      elements.push_back(e);
    } else if (keyword == "property") {
      if (elements.empty()) throw fail("property before any element");
      std::string type;
      words >> type;
      Property p;
      if (type == "list") {
        std::string countType, itemType;
        words >> countType >> itemType >> p.name;
        p.listCount = scalarType(countType);
        const auto item = scalarType(itemType);
        if (!p.listCount || !item || io::isFloat(*p.listCount)) throw fail("malformed list property");
        p.type = *item;
      } else {
        const auto scalar = scalarType(type);
        words >> p.name;
        if (!scalar) throw fail(fmt::format("unknown property type '{}'", type));
        p.type = *scalar;
      }
      if (!words) throw fail("malformed property line");
      p.axis = p.name == "x" ? 0 : p.name == "y" ? 1 : p.name == "z" ? 2 : -1;
      elements.back().properties.push_back(p);
    } else if (keyword != "ply" && keyword != "comment" && keyword != "obj_info" && !keyword.empty()) {
      throw fail(fmt::format("unexpected '{}' in the PLY header", keyword));
    }
  }
  if (!encoding) throw Error(fmt::format("{}: the PLY header has no format line", name));

  // Each value takes at least one byte (binary) or two (a digit and a separator), so a count the
  // remaining bytes cannot hold is rejected before anything is allocated.
  const std::size_t available = bytes.size() - dataStart;
  const std::size_t perValue = *encoding == Encoding::Ascii ? 2 : 1;
  for (const Element& e : elements)
    if (!e.properties.empty() && e.count > available / (perValue * e.properties.size()))
      throw Error(fmt::format("{}: the header declares {} {} elements, more than the file can hold (truncated?)", name,
                              e.count, e.name));

  TriMesh mesh;
  DataReader data(name, bytes, dataStart, *encoding);
  bool haveVertices = false;
  for (const Element& e : elements) {
    const bool isVertex = e.name == "vertex", isFace = e.name == "face";
    // Without properties an element takes no bytes, so nothing above bounds its count.
    if (e.properties.empty() && !isVertex) continue;
    if (isVertex) {
      for (const char* axis : {"x", "y", "z"})
        if (std::none_of(e.properties.begin(), e.properties.end(), [&](const Property& p) { return p.name == axis; }))
          throw Error(fmt::format("{}: the vertex element has no property {}", name, axis));
      haveVertices = true;
      mesh.vertices.resize(e.count, Vec3::Zero());
    }
    for (std::size_t i = 0; i < e.count; ++i)
      for (std::size_t p = 0; p < e.properties.size(); ++p) {
        const Property& prop = e.properties[p];
        if (!prop.listCount) {
          const double value = data.read(prop.type);
          if (isVertex && prop.axis >= 0) mesh.vertices[i][prop.axis] = static_cast<float>(value);
          continue;
        }
        const double n = data.read(*prop.listCount);
        if (!(n >= 0 && n <= 1000 && n == std::floor(n)))  // NaN too
          throw Error(fmt::format("{}: {} {} has a list of {} items", name, e.name, i, n));
        // Only a face's vertex indices are kept; other lists (texture coordinates, ...) are read past.
        const bool indices = isFace && (prop.name == "vertex_indices" || prop.name == "vertex_index");
        std::vector<Index> polygon(indices ? static_cast<std::size_t>(n) : 0);
        for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
          const double value = data.read(prop.type);
          if (!indices) continue;
          if (!(value >= 0 && value < double(mesh.vertices.size()) && value == std::floor(value)))
            throw Error(
                fmt::format("{}: face {} refers to vertex {}, but there are {} vertices (numbered from 0 in PLY)", name,
                            i + 1, value, mesh.vertices.size()));
          polygon[k] = static_cast<Index>(value);
        }
        if (!indices) continue;
        if (!haveVertices) throw Error(fmt::format("{}: faces come before vertices", name));
        if (polygon.size() < 3)
          throw Error(fmt::format("{}: face {} has only {} corners", name, i + 1, polygon.size()));
        for (std::size_t k = 1; k + 1 < polygon.size(); ++k)
          mesh.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
      }
  }
  return mesh;
}

}  // namespace vrd
