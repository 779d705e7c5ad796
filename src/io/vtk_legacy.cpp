// VTK legacy .vtk, DATASET UNSTRUCTURED_GRID, ASCII or BINARY (big-endian numbers right after the
// line that announces them). Versions before 5 list cells as "n i0 ... in-1" records; 5.x as OFFSETS
// and CONNECTIVITY arrays. Reading stops at POINT_DATA or CELL_DATA: the geometry comes first.

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <limits>

#include "io/binary.h"
#include "io/tet_formats.h"
#include "io/text_out.h"
#include "vrdeform/core/text_tokens.h"
#include "vrdeform/error.h"

namespace vrd::io {
namespace {

std::string upper(std::string_view s) {
  std::string u(s);
  for (char& c : u) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return u;
}

struct LegacyVtkReader {
  TextTokens& in;
  bool binary = false;

  std::size_t countOf(std::string_view what) {
    const std::int64_t n = in.integer(what);
    if (n < 0) in.fail(fmt::format("{} is negative ({})", what, n));
    return static_cast<std::size_t>(n);
  }

  Scalar scalar(std::string_view what) {
    const std::string_view name = in.next(what);
    const auto s = scalarFromLegacyName(name);
    if (!s) in.fail(fmt::format("unknown data type '{}' for {}", printable(name), what));
    return *s;
  }

  // `count` numbers of type `type` as T (double or std::int64_t), after the line announcing them.
  template <typename T>
  std::vector<T> values(std::size_t count, Scalar type, std::string_view what) {
    if constexpr (!std::is_floating_point_v<T>)
      if (isFloat(type)) in.fail(fmt::format("{} must have an integer type", what));
    std::vector<T> out;
    if (!binary) {
      in.checkFits(count, fmt::format("the number of {}", what), 1);
      out.resize(count);
      for (T& v : out) {
        if constexpr (std::is_floating_point_v<T>)
          v = in.real(what);
        else
          v = in.integer(what);
      }
      return out;
    }
    in.restOfLine();
    const std::size_t size = sizeOf(type);
    if (count > in.remaining() / size)
      in.fail(fmt::format("{} {} take {} bytes, but only {} are left in the file", count, what,
                          static_cast<double>(count) * static_cast<double>(size), in.remaining()));
    out.resize(count);
    const auto* p = reinterpret_cast<const unsigned char*>(in.text().data() + in.offset());
    for (std::size_t k = 0; k < count; ++k) out[k] = loadScalar<T>(p + k * size, type, true);
    in.skipBytes(count * size);
    return out;
  }

  void skipField() {
    in.next("the field name");
    const std::size_t arrays = countOf("the number of field arrays");
    for (std::size_t a = 0; a < arrays; ++a) {
      in.next("the array name");
      const std::size_t components = countOf("the number of components");
      const std::size_t tuples = countOf("the number of tuples");
      const Scalar type = scalar("the array type");
      if (tuples != 0 && components > std::numeric_limits<std::size_t>::max() / tuples)
        in.fail("the field array is too large");
      values<double>(components * tuples, type, "field values");
    }
  }

  void skipMetadata() {
    in.restOfLine();
    while (in.remaining() > 0) {
      const std::string_view line = in.restOfLine();
      if (line.find_first_not_of(" \t\r") == std::string_view::npos) return;
    }
  }
};

}  // namespace

TetMesh readVtkLegacy(std::string_view text, const std::string& name, std::vector<Triangle>* faces) {
  TextTokens in(text, name);
  if (text.empty()) in.fail("the file is empty, expected '# vtk DataFile Version'");
  const std::string_view header = in.restOfLine();
  constexpr std::string_view kMagic = "# vtk DataFile Version";
  if (header.size() < kMagic.size() || upper(header.substr(0, kMagic.size())) != upper(kMagic))
    in.fail(fmt::format("expected '{}' (a VTK legacy file), found '{}'", kMagic, printable(header)));
  double version = 0;
  std::string_view number = header.substr(kMagic.size());
  while (!number.empty() && (number.front() == ' ' || number.front() == '\t')) number.remove_prefix(1);
  while (!number.empty() && std::isspace(static_cast<unsigned char>(number.back()))) number.remove_suffix(1);
  if (!parseReal(number, version)) in.fail(fmt::format("unreadable version '{}'", printable(number)));
  in.restOfLine();  // the title

  LegacyVtkReader reader{in};
  const std::string mode = upper(in.next("ASCII or BINARY"));
  if (mode != "ASCII" && mode != "BINARY") in.fail(fmt::format("expected ASCII or BINARY, found '{}'", mode));
  reader.binary = mode == "BINARY";
  if (upper(in.next("DATASET")) != "DATASET") in.fail("expected DATASET");
  const std::string dataset = upper(in.next("the dataset type"));
  if (dataset != "UNSTRUCTURED_GRID")
    in.fail(fmt::format("dataset {} is not supported, expected UNSTRUCTURED_GRID", printable(dataset)));

  TetMesh mesh;
  bool havePoints = false, haveCells = false, haveTypes = false;
  std::vector<std::int64_t> offsets{0}, connectivity, types;
  while (!in.atEnd()) {
    const std::string keyword = upper(in.next("a keyword"));
    if (keyword == "POINTS") {
      if (havePoints) in.fail("a second POINTS section");
      const std::size_t n = reader.countOf("the number of points");
      const std::vector<double> xyz = reader.values<double>(n <= SIZE_MAX / 3 ? 3 * n : SIZE_MAX,
                                                            reader.scalar("the point type"), "point coordinates");
      mesh.vertices.resize(n);
      for (std::size_t v = 0; v < n; ++v) {
        mesh.vertices[v] = Vec3(static_cast<float>(xyz[3 * v]), static_cast<float>(xyz[3 * v + 1]),
                                static_cast<float>(xyz[3 * v + 2]));
        if (!isFinite(mesh.vertices[v]))
          in.fail(fmt::format("point {} has a non-finite or out-of-range coordinate ({}, {}, {})", v, xyz[3 * v],
                              xyz[3 * v + 1], xyz[3 * v + 2]));
      }
      havePoints = true;
    } else if (keyword == "CELLS") {
      if (haveCells) in.fail("a second CELLS section");
      const std::size_t a = reader.countOf("the number of cells"), b = reader.countOf("the size of the cell list");
      if (version < 5) {
        // Records "n i0 ... in-1"; b counts every number.
        const std::vector<std::int64_t> list = reader.values<std::int64_t>(b, Scalar::Int32, "cell list numbers");
        std::size_t k = 0;
        for (std::size_t c = 0; c < a; ++c) {
          if (k >= list.size()) in.fail(fmt::format("the cell list ends after {} of {} cells", c, a));
          const std::int64_t size = list[k++];
          if (size < 0 || static_cast<std::uint64_t>(size) > list.size() - k)
            in.fail(fmt::format("cell {} has {} points, more than the cell list holds", c, size));
          connectivity.insert(connectivity.end(), list.begin() + static_cast<std::ptrdiff_t>(k),
                              list.begin() + static_cast<std::ptrdiff_t>(k) + size);
          k += static_cast<std::size_t>(size);
          offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
        }
        if (k != list.size())
          in.fail(fmt::format("the cell list has {} numbers, but its {} cells use {}", list.size(), a, k));
      } else {
        if (upper(in.next("OFFSETS")) != "OFFSETS") in.fail("expected OFFSETS");
        offsets = reader.values<std::int64_t>(a, reader.scalar("the offset type"), "cell offsets");
        if (upper(in.next("CONNECTIVITY")) != "CONNECTIVITY") in.fail("expected CONNECTIVITY");
        connectivity = reader.values<std::int64_t>(b, reader.scalar("the connectivity type"), "cell connectivity");
        if (offsets.empty()) offsets.push_back(0);
        if (offsets.front() != 0) in.fail("the first cell offset is not 0");
        for (std::size_t c = 1; c < offsets.size(); ++c)
          if (offsets[c] < offsets[c - 1] || offsets[c] > static_cast<std::int64_t>(connectivity.size()))
            in.fail(fmt::format("cell offset {} ({}) is out of order or beyond the {} connectivity entries", c,
                                offsets[c], connectivity.size()));
      }
      haveCells = true;
    } else if (keyword == "CELL_TYPES") {
      if (haveTypes) in.fail("a second CELL_TYPES section");
      types = reader.values<std::int64_t>(reader.countOf("the number of cell types"), Scalar::Int32, "cell types");
      haveTypes = true;
    } else if (keyword == "FIELD") {
      reader.skipField();
    } else if (keyword == "METADATA") {
      reader.skipMetadata();
    } else if (keyword == "POINT_DATA" || keyword == "CELL_DATA") {
      break;
    } else {
      in.fail(fmt::format("unexpected keyword '{}'", printable(keyword)));
    }
  }
  if (!havePoints || !haveCells || !haveTypes)
    throw Error(fmt::format("{}: missing {}", name, !havePoints ? "POINTS" : !haveCells ? "CELLS" : "CELL_TYPES"));
  const std::size_t cells = offsets.size() - 1;
  if (types.size() != cells) throw Error(fmt::format("{}: {} cell types for {} cells", name, types.size(), cells));

  for (std::size_t c = 0; c < cells; ++c) {
    const std::int64_t type = types[c];
    if (type == kVtkQuadraticTet || type == kVtkLagrangeTet)
      throw Error(fmt::format("{}: second-order tets are not supported (cell {} has type {})", name, c, type));
    if (type != kVtkTet && type != kVtkTriangle) continue;
    const std::size_t size = type == kVtkTet ? 4 : 3;
    if (static_cast<std::size_t>(offsets[c + 1] - offsets[c]) != size)
      throw Error(fmt::format("{}: cell {} of type {} has {} points, expected {}", name, c, type,
                              offsets[c + 1] - offsets[c], size));
    std::array<Index, 4> idx{};
    for (std::size_t k = 0; k < size; ++k) {
      const std::int64_t i = connectivity[static_cast<std::size_t>(offsets[c]) + k];
      if (i < 0 || static_cast<std::uint64_t>(i) >= mesh.vertices.size())
        throw Error(fmt::format("{}: cell {} refers to point {}, but there are {} points (numbered from 0)", name, c, i,
                                mesh.vertices.size()));
      idx[k] = static_cast<Index>(i);
    }
    if (type == kVtkTet)
      mesh.tets.push_back(idx);
    else if (faces)
      faces->push_back({idx[0], idx[1], idx[2]});
  }
  return mesh;
}

void writeVtkLegacy(std::ostream& stream, const TetMesh& mesh) {
  TextOut out(stream);
  out.print("# vtk DataFile Version 3.0\nvrdeform tet mesh\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS {} float\n",
            mesh.vertices.size());
  for (const Vec3& v : mesh.vertices) {
    out.coordinates(v);
    out.print("\n");
  }
  out.print("CELLS {} {}\n", mesh.tets.size(), 5 * mesh.tets.size());
  for (const Tet& t : mesh.tets) out.print("4 {} {} {} {}\n", t[0], t[1], t[2], t[3]);
  out.print("CELL_TYPES {}\n", mesh.tets.size());
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) out.print("10\n");
}

}  // namespace vrd::io
