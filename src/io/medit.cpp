// MEDIT .mesh (ASCII): keyword sections, each a count and that many items with a trailing reference
// number; vertices are numbered from 1. '#' starts a comment. Keywords are matched in any case.

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <optional>

#include "io/tet_formats.h"
#include "io/text_out.h"
#include "vrdeform/core/text_tokens.h"
#include "vrdeform/error.h"

namespace vrd::io {
namespace {

bool same(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

// Sections we skip, with the numbers per item.
struct Skipped {
  std::string_view keyword;
  std::size_t numbers;
};
constexpr Skipped kSkipped[] = {
    {"Edges", 3},
    {"Quadrilaterals", 5},
    {"Hexahedra", 9},
    {"Prisms", 7},
    {"Pyramids", 6},
    {"Corners", 1},
    {"Ridges", 1},
    {"RequiredVertices", 1},
    {"RequiredEdges", 1},
    {"RequiredTriangles", 1},
    {"RequiredQuadrilaterals", 1},
    {"RequiredTetrahedra", 1},
    {"Normals", 3},
    {"Tangents", 3},
    {"NormalAtVertices", 2},
    {"NormalAtTriangleVertices", 3},
    {"NormalAtQuadrilateralVertices", 3},
    {"TangentAtEdgeVertices", 3},
    {"TangentAtVertices", 2},
    {"EdgesP2", 4},
    {"TrianglesP2", 7},
    {"QuadrilateralsQ2", 10},
    {"HexahedraQ2", 28},
};

template <std::size_t N>
std::array<std::int64_t, N> readElement(TextTokens& in, std::optional<std::size_t> vertexCount, const char* element,
                                        std::size_t number) {
  std::array<std::int64_t, N> ids;
  for (std::size_t k = 0; k < N; ++k) {
    ids[k] = in.integer("a vertex number");
    const bool bad = ids[k] < 1 || (vertexCount && ids[k] > static_cast<std::int64_t>(*vertexCount));
    if (bad)
      in.fail(vertexCount
                  ? fmt::format("{} {} refers to vertex {}, but the vertices are numbered 1 to {}", element, number,
                                ids[k], *vertexCount)
                  : fmt::format("{} {} refers to vertex {}; vertices are numbered from 1", element, number, ids[k]));
  }
  in.integer("a reference number");
  return ids;
}

template <std::size_t N>
void toIndices(const std::vector<std::array<std::int64_t, N>>& ids, std::vector<std::array<Index, N>>& out,
               std::size_t vertexCount, const std::string& name, const char* element) {
  out.resize(ids.size());
  for (std::size_t e = 0; e < ids.size(); ++e)
    for (std::size_t k = 0; k < N; ++k) {
      if (ids[e][k] > static_cast<std::int64_t>(vertexCount))
        throw Error(fmt::format("{}: {} {} refers to vertex {}, but the vertices are numbered 1 to {}", name, element,
                                e + 1, ids[e][k], vertexCount));
      out[e][k] = static_cast<Index>(ids[e][k] - 1);
    }
}

}  // namespace

TetMesh readMedit(std::string_view text, const std::string& name, std::vector<Triangle>* faces) {
  TextTokens in(text, name, '#');
  if (in.atEnd()) in.fail("the file is empty, expected MeshVersionFormatted");
  const std::string_view first = in.next("MeshVersionFormatted");
  if (!same(first, "MeshVersionFormatted"))
    in.fail(fmt::format("expected MeshVersionFormatted (a MEDIT .mesh file), found '{}'", printable(first)));
  in.integer("the mesh version", 1, 4);

  TetMesh mesh;
  std::optional<std::size_t> vertexCount;
  std::vector<std::array<std::int64_t, 4>> tets;
  std::vector<std::array<std::int64_t, 3>> triangles;
  while (!in.atEnd()) {
    const std::string_view keyword = in.next("a keyword");
    if (same(keyword, "End")) break;
    if (same(keyword, "Dimension")) {
      const std::int64_t dim = in.integer("the dimension");
      if (dim != 3) in.fail(fmt::format("dimension is {}, expected 3 (a tet mesh)", dim));
    } else if (same(keyword, "Vertices")) {
      if (vertexCount) in.fail("a second Vertices section");
      const std::size_t n = in.count("the number of vertices", 4);
      mesh.vertices.resize(n);
      for (std::size_t v = 0; v < n; ++v) {
        for (int c = 0; c < 3; ++c) {
          const double x = in.real("a coordinate");
          mesh.vertices[v][c] = static_cast<float>(x);
          if (!std::isfinite(mesh.vertices[v][c]))
            in.fail(fmt::format("vertex {} has a non-finite or out-of-range coordinate ({})", v + 1, x));
        }
        in.integer("a reference number");
      }
      vertexCount = n;
    } else if (same(keyword, "Tetrahedra")) {
      const std::size_t n = in.count("the number of tetrahedra", 5);
      tets.reserve(tets.size() + n);
      for (std::size_t t = 0; t < n; ++t) tets.push_back(readElement<4>(in, vertexCount, "tetrahedron", t + 1));
    } else if (same(keyword, "Triangles")) {
      const std::size_t n = in.count("the number of triangles", 4);
      triangles.reserve(triangles.size() + n);
      for (std::size_t t = 0; t < n; ++t) triangles.push_back(readElement<3>(in, vertexCount, "triangle", t + 1));
    } else if (same(keyword, "TetrahedraP2")) {
      in.fail("second-order tets are not supported (TetrahedraP2)");
    } else {
      const auto skipped = std::find_if(std::begin(kSkipped), std::end(kSkipped),
                                        [&](const Skipped& s) { return same(s.keyword, keyword); });
      if (skipped == std::end(kSkipped)) in.fail(fmt::format("unknown MEDIT keyword '{}'", printable(keyword)));
      const std::size_t n = in.count(fmt::format("the number of {}", skipped->keyword), skipped->numbers);
      for (std::size_t k = 0; k < n * skipped->numbers; ++k) in.real("a number");
    }
  }
  if (!vertexCount) throw Error(fmt::format("{}: no Vertices section", name));
  // Sections may come in any order; indices in sections before Vertices are checked here.
  toIndices(tets, mesh.tets, *vertexCount, name, "tetrahedron");
  if (faces) toIndices(triangles, *faces, *vertexCount, name, "triangle");
  return mesh;
}

void writeMedit(std::ostream& stream, const TetMesh& mesh) {
  TextOut out(stream);
  out.print("MeshVersionFormatted 2\nDimension 3\n\nVertices\n{}\n", mesh.vertices.size());
  for (const Vec3& v : mesh.vertices) {
    out.coordinates(v);
    out.print(" 0\n");
  }
  out.print("\nTetrahedra\n{}\n", mesh.tets.size());
  for (const Tet& t : mesh.tets) out.print("{} {} {} {} 0\n", t[0] + 1, t[1] + 1, t[2] + 1, t[3] + 1);
  out.print("\nEnd\n");
}

}  // namespace vrd::io
