// TetGen's .node/.ele/.face: a header line with counts, then one numbered item per line; '#' starts a
// comment. Numbering starts at 0 or 1, as the first node says; .ele and .face use the same base.

#include <fmt/format.h>

#include <array>
#include <cmath>

#include "io/tet_formats.h"
#include "io/text_out.h"
#include "vrdeform/core/atomic_file.h"
#include "vrdeform/core/text_tokens.h"
#include "vrdeform/error.h"
#include "vrdeform/mesh/boundary.h"

namespace vrd::io {
namespace {

std::filesystem::path sibling(const std::filesystem::path& path, const char* ext) {
  std::filesystem::path p = path;
  return p.replace_extension(ext);
}

// Reads `count` node numbers of one element, converted to 0-based indices.
template <std::size_t N>
std::array<Index, N> readNodes(TextTokens& in, std::int64_t base, std::size_t nodeCount, const char* element,
                               std::size_t number) {
  std::array<Index, N> nodes;
  for (std::size_t k = 0; k < N; ++k) {
    const std::int64_t id = in.integer("a node number");
    if (id < base || id - base >= static_cast<std::int64_t>(nodeCount))
      in.fail(fmt::format("{} {} refers to node {}, but the nodes are numbered {} to {}", element, number, id, base,
                          base + static_cast<std::int64_t>(nodeCount) - 1));
    nodes[k] = static_cast<Index>(id - base);
  }
  return nodes;
}

void skipTokens(TextTokens& in, std::int64_t n, const char* what) {
  for (std::int64_t k = 0; k < n; ++k) in.real(what);
}

}  // namespace

TetMesh readTetGen(const std::filesystem::path& path, std::vector<Triangle>* faces) {
  const std::filesystem::path nodePath = sibling(path, ".node"), elePath = sibling(path, ".ele"),
                              facePath = sibling(path, ".face");
  const std::string node = readFileBytes(nodePath);
  if (!std::filesystem::exists(elePath))
    throw Error(fmt::format("{}: cannot read the tets: {} is missing", nodePath.string(), elePath.string()));
  const std::string ele = readFileBytes(elePath);
  std::string face;
  const bool withFaces = faces && std::filesystem::exists(facePath);
  if (withFaces) face = readFileBytes(facePath);
  const TetGenText faceText{face, facePath.string()};
  return parseTetGen({node, nodePath.string()}, {ele, elePath.string()}, withFaces ? &faceText : nullptr, faces);
}

TetMesh parseTetGen(const TetGenText& node, const TetGenText& ele, const TetGenText* face,
                    std::vector<Triangle>* faces) {
  TetMesh mesh;
  std::int64_t base = 0;
  {
    TextTokens in(node.text, node.name, '#');
    if (in.atEnd()) in.fail("the file is empty, expected the number of nodes");
    const std::size_t n = in.count("the number of nodes", 4);
    const std::int64_t dim = in.integer("the dimension");
    if (dim != 3) in.fail(fmt::format("dimension is {}, expected 3 (a tet mesh)", dim));
    const std::int64_t attributes = in.integer("the number of attributes", 0, 1 << 20);
    const std::int64_t markers = in.integer("the number of boundary markers", 0, 1);
    in.checkFits(n, "the number of nodes", static_cast<std::size_t>(4 + attributes + markers));
    if (n == 0) in.fail("no nodes (nodes kept in a .poly file are not supported)");
    mesh.vertices.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      const std::int64_t id = in.integer("a node number");
      if (k == 0) {
        if (id != 0 && id != 1) in.fail(fmt::format("the first node is numbered {}, expected 0 or 1", id));
        base = id;
      } else if (id != base + static_cast<std::int64_t>(k)) {
        in.fail(fmt::format("node numbered {}, expected {} (nodes must be numbered in order)", id,
                            base + static_cast<std::int64_t>(k)));
      }
      for (int c = 0; c < 3; ++c) {
        const double x = in.real("a coordinate");
        mesh.vertices[k][c] = static_cast<float>(x);
        if (!std::isfinite(mesh.vertices[k][c]))
          in.fail(fmt::format("node {} has a non-finite or out-of-range coordinate ({})", id, x));
      }
      skipTokens(in, attributes + markers, "an attribute or boundary marker");
    }
  }

  {
    TextTokens in(ele.text, ele.name, '#');
    if (in.atEnd()) in.fail("the file is empty, expected the number of tetrahedra");
    const std::size_t n = in.count("the number of tetrahedra", 5);
    const std::int64_t nodesPerTet = in.integer("the number of nodes per tetrahedron");
    if (nodesPerTet == 10) in.fail("second-order tets are not supported (10 nodes per tetrahedron)");
    if (nodesPerTet != 4) in.fail(fmt::format("{} nodes per tetrahedron, expected 4", nodesPerTet));
    const std::int64_t attributes = in.integer("the number of attributes", 0, 1 << 20);
    in.checkFits(n, "the number of tetrahedra", static_cast<std::size_t>(5 + attributes));
    mesh.tets.resize(n);
    for (std::size_t t = 0; t < n; ++t) {
      const std::int64_t id = in.integer("a tetrahedron number");
      mesh.tets[t] = readNodes<4>(in, base, mesh.vertices.size(), "tetrahedron", static_cast<std::size_t>(id));
      skipTokens(in, attributes, "an attribute");
    }
  }

  if (faces && face) {
    TextTokens in(face->text, face->name, '#');
    if (in.atEnd()) in.fail("the file is empty, expected the number of faces");
    const std::size_t n = in.count("the number of faces", 4);
    const std::int64_t markers = in.integer("the number of boundary markers", 0, 1);
    in.checkFits(n, "the number of faces", static_cast<std::size_t>(4 + markers));
    faces->resize(n);
    for (std::size_t f = 0; f < n; ++f) {
      const std::int64_t id = in.integer("a face number");
      (*faces)[f] = readNodes<3>(in, base, mesh.vertices.size(), "face", static_cast<std::size_t>(id));
      skipTokens(in, markers, "a boundary marker");
    }
  }
  checkReadMesh(mesh, ele.name);
  return mesh;
}

void writeTetGen(const std::filesystem::path& path, const TetMesh& mesh) {
  const std::vector<Triangle> boundary = boundaryFaces(mesh);
  AtomicFile node(sibling(path, ".node")), ele(sibling(path, ".ele")), face(sibling(path, ".face"));
  {
    TextOut out(node.stream());
    out.print("# {} nodes, 3D, no attributes, no boundary markers; written by vrdeform\n", mesh.vertices.size());
    out.print("{} 3 0 0\n", mesh.vertices.size());
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
      out.print("{} ", v + 1);
      out.coordinates(mesh.vertices[v]);
      out.print("\n");
    }
  }
  {
    TextOut out(ele.stream());
    out.print("{} 4 0\n", mesh.tets.size());
    for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
      const Tet& tet = mesh.tets[t];
      out.print("{} {} {} {} {}\n", t + 1, tet[0] + 1, tet[1] + 1, tet[2] + 1, tet[3] + 1);
    }
  }
  {
    TextOut out(face.stream());
    out.print("{} 0\n", boundary.size());
    for (std::size_t f = 0; f < boundary.size(); ++f)
      out.print("{} {} {} {}\n", f + 1, boundary[f][0] + 1, boundary[f][1] + 1, boundary[f][2] + 1);
  }
  // Only once all three are complete does any of them replace what was there.
  node.commit();
  ele.commit();
  face.commit();
}

}  // namespace vrd::io
