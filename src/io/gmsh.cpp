// Gmsh .msh, ASCII, format 2.x and 4.x: $Section ... $EndSection blocks. Nodes carry tags (any
// positive numbers, not necessarily contiguous), mapped here to indices in the order the nodes
// appear. Format 4 groups nodes and elements in entity blocks. One element per line.

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "io/tet_formats.h"
#include "io/text_out.h"
#include "vrdeform/core/text_tokens.h"
#include "vrdeform/error.h"

namespace vrd::io {
namespace {

constexpr int kTriangle = 2, kTet = 4;
constexpr bool isHigherOrderTet(std::int64_t type) { return type == 11 || type == 29 || type == 30 || type == 31; }

// Node tags to dense indices: a table when the tags are nearly contiguous, a hash map otherwise.
class NodeTags {
 public:
  void build(const std::vector<std::int64_t>& tags, TextTokens& in) {
    if (tags.empty()) return;
    const auto [lo, hi] = std::minmax_element(tags.begin(), tags.end());
    min_ = *lo;
    const bool dense = static_cast<std::uint64_t>(*hi - *lo) < 4 * tags.size() + 1024;
    if (dense) table_.assign(static_cast<std::size_t>(*hi - *lo) + 1, kNone);
    for (std::size_t i = 0; i < tags.size(); ++i) {
      bool fresh;
      if (dense) {
        Index& slot = table_[static_cast<std::size_t>(tags[i] - min_)];
        fresh = slot == kNone;
        slot = static_cast<Index>(i);
      } else {
        fresh = map_.emplace(tags[i], static_cast<Index>(i)).second;
      }
      if (!fresh) in.fail(fmt::format("node tag {} appears twice in $Nodes", tags[i]));
    }
  }
  Index find(std::int64_t tag) const {
    if (!table_.empty()) {
      if (tag < min_ || static_cast<std::uint64_t>(tag - min_) >= table_.size()) return kNone;
      return table_[static_cast<std::size_t>(tag - min_)];
    }
    const auto it = map_.find(tag);
    return it == map_.end() ? kNone : it->second;
  }
  static constexpr Index kNone = std::numeric_limits<Index>::max();

 private:
  std::int64_t min_ = 0;
  std::vector<Index> table_;
  std::unordered_map<std::int64_t, Index> map_;
};

struct GmshReader {
  TextTokens& in;
  std::vector<std::int64_t> tags;
  NodeTags nodeTags;
  TetMesh mesh;
  std::vector<Triangle>* faces;
  bool haveNodes = false;

  void expect(std::string_view token) {
    const std::string_view found = in.next(token);
    if (found != token) in.fail(fmt::format("expected {}, found '{}'", token, printable(found)));
  }

  std::int64_t tag(std::string_view what) { return in.integer(what, 1, std::numeric_limits<std::int64_t>::max()); }

  void readNode(std::size_t i, std::int64_t nodeTag, std::int64_t extraNumbers) {
    tags[i] = nodeTag;
    for (int c = 0; c < 3; ++c) {
      const double x = in.real("a coordinate");
      mesh.vertices[i][c] = static_cast<float>(x);
      if (!std::isfinite(mesh.vertices[i][c]))
        in.fail(fmt::format("node {} has a non-finite or out-of-range coordinate ({})", nodeTag, x));
    }
    for (std::int64_t k = 0; k < extraNumbers; ++k) in.real("a parametric coordinate");
  }

  void startNodes(std::size_t n) {
    if (haveNodes) in.fail("a second $Nodes section");
    if (n >= std::numeric_limits<Index>::max()) in.fail(fmt::format("{} nodes are too many", n));
    mesh.vertices.resize(n);
    tags.resize(n);
  }

  void readNodesV2() {
    const std::size_t n = in.count("the number of nodes", 4);
    startNodes(n);
    for (std::size_t i = 0; i < n; ++i) readNode(i, tag("a node tag"), 0);
  }

  void readNodesV4(bool v41) {
    const std::size_t blocks = in.count("the number of entity blocks", 4);
    const std::size_t n = in.count("the number of nodes", 4);
    if (v41) {
      in.integer("the smallest node tag");
      in.integer("the largest node tag");
    }
    startNodes(n);
    std::size_t done = 0;
    for (std::size_t b = 0; b < blocks; ++b) {
      std::int64_t dim;
      if (v41) {
        dim = in.integer("the entity dimension", 0, 3);
        in.integer("the entity tag");
      } else {
        in.integer("the entity tag");
        dim = in.integer("the entity dimension", 0, 3);
      }
      const bool parametric = in.integer("the parametric flag", 0, 1) == 1;
      const std::size_t count = in.count("the number of nodes in the block", 4);
      if (count > n - done)
        in.fail(fmt::format("the entity blocks hold more nodes than the {} that $Nodes declares", n));
      const std::int64_t extra = parametric ? dim : 0;
      if (v41) {
        for (std::size_t i = 0; i < count; ++i) tags[done + i] = tag("a node tag");
        for (std::size_t i = 0; i < count; ++i) readNode(done + i, tags[done + i], extra);
      } else {
        for (std::size_t i = 0; i < count; ++i) readNode(done + i, tag("a node tag"), extra);
      }
      done += count;
    }
    if (done != n) in.fail(fmt::format("the entity blocks hold {} nodes, but $Nodes declares {}", done, n));
  }

  template <std::size_t N>
  std::array<Index, N> readElementNodes(const char* element, std::int64_t elementTag) {
    if (!haveNodes) in.fail("$Elements comes before $Nodes");
    std::array<Index, N> nodes;
    for (std::size_t k = 0; k < N; ++k) {
      const std::int64_t nodeTag = in.integer("a node tag");
      nodes[k] = nodeTags.find(nodeTag);
      if (nodes[k] == NodeTags::kNone)
        in.fail(fmt::format("{} {} refers to node {}, which is not in $Nodes", element, elementTag, nodeTag));
    }
    return nodes;
  }

  // Reads the nodes of an element of `type` after its tags, or skips the rest of its line.
  void readElement(std::int64_t type, std::int64_t elementTag) {
    if (type == kTet) {
      mesh.tets.push_back(readElementNodes<4>("tetrahedron", elementTag));
    } else if (type == kTriangle) {
      const Triangle t = readElementNodes<3>("triangle", elementTag);
      if (faces) faces->push_back(t);
    } else if (isHigherOrderTet(type)) {
      in.fail(fmt::format("second-order tets are not supported (element {} has type {})", elementTag, type));
    } else {
      in.skipLine();
    }
  }

  void readElementsV2() {
    const std::size_t n = in.count("the number of elements", 4);
    for (std::size_t e = 0; e < n; ++e) {
      const std::int64_t elementTag = in.integer("an element tag");
      const std::int64_t type = in.integer("an element type");
      if (type != kTet && type != kTriangle && !isHigherOrderTet(type)) {
        in.skipLine();
        continue;
      }
      const std::int64_t tagCount = in.integer("the number of element tags", 0, 1 << 20);
      for (std::int64_t k = 0; k < tagCount; ++k) in.integer("an element tag");
      readElement(type, elementTag);
    }
  }

  void readElementsV4(bool v41) {
    const std::size_t blocks = in.count("the number of entity blocks", 4);
    const std::size_t n = in.count("the number of elements", 2);
    if (v41) {
      in.integer("the smallest element tag");
      in.integer("the largest element tag");
    }
    std::size_t done = 0;
    for (std::size_t b = 0; b < blocks; ++b) {
      if (v41) {
        in.integer("the entity dimension", 0, 3);
        in.integer("the entity tag");
      } else {
        in.integer("the entity tag");
        in.integer("the entity dimension", 0, 3);
      }
      const std::int64_t type = in.integer("the element type");
      const std::size_t count = in.count("the number of elements in the block", 2);
      if (count > n - done)
        in.fail(fmt::format("the entity blocks hold more elements than the {} that $Elements declares", n));
      if (type != kTet && type != kTriangle && !isHigherOrderTet(type)) {
        in.skipLine();
        for (std::size_t i = 0; i < count; ++i) in.skipLine();
      } else {
        for (std::size_t i = 0; i < count; ++i) readElement(type, in.integer("an element tag"));
      }
      done += count;
    }
    if (done != n) in.fail(fmt::format("the entity blocks hold {} elements, but $Elements declares {}", done, n));
  }

  void skipSection(std::string_view section) {
    const std::string end = fmt::format("$End{}", section.substr(1));
    while (true) {
      if (in.atEnd()) in.fail(fmt::format("unexpected end of file in {} (no {})", section, end));
      if (in.next(end) == end) return;
    }
  }
};

}  // namespace

TetMesh readGmsh(std::string_view text, const std::string& name, std::vector<Triangle>* faces) {
  TextTokens in(text, name);
  if (in.atEnd()) in.fail("the file is empty, expected $MeshFormat");
  const std::string_view first = in.next("$MeshFormat");
  if (first == "$NOD") in.fail("Gmsh format 1 is not supported (save as format 2.2 or 4.1)");
  if (first != "$MeshFormat") in.fail(fmt::format("expected $MeshFormat (a Gmsh file), found '{}'", printable(first)));
  const std::string_view version = in.next("the format version");
  const bool v2 = version.starts_with("2"), v40 = version == "4" || version == "4.0", v41 = version == "4.1";
  double parsed;
  if (!(v2 || v40 || v41) || !parseReal(version, parsed))
    in.fail(fmt::format("Gmsh format version '{}' is not supported (2.x, 4.0, 4.1)", printable(version)));
  if (in.integer("the file type (0: ASCII)", 0, 1) == 1) in.fail("binary Gmsh files are not supported (save as ASCII)");
  in.integer("the data size");

  GmshReader reader{in, {}, {}, {}, faces};
  reader.expect("$EndMeshFormat");
  while (!in.atEnd()) {
    const std::string_view section = in.next("a section");
    if (section == "$Nodes") {
      if (v2)
        reader.readNodesV2();
      else
        reader.readNodesV4(v41);
      reader.expect("$EndNodes");
      reader.nodeTags.build(reader.tags, in);
      reader.haveNodes = true;
    } else if (section == "$Elements") {
      if (v2)
        reader.readElementsV2();
      else
        reader.readElementsV4(v41);
      reader.expect("$EndElements");
    } else if (section.size() > 1 && section.front() == '$' && !section.starts_with("$End")) {
      reader.skipSection(section);
    } else {
      in.fail(fmt::format("expected a section such as $Nodes, found '{}'", printable(section)));
    }
  }
  if (!reader.haveNodes) throw Error(fmt::format("{}: no $Nodes section", name));
  return std::move(reader.mesh);
}

void writeGmsh(std::ostream& stream, const TetMesh& mesh, GmshVersion version) {
  TextOut out(stream);
  const std::size_t n = mesh.vertices.size(), m = mesh.tets.size();
  if (version == GmshVersion::V2_2) {
    out.print("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n{}\n", n);
    for (std::size_t v = 0; v < n; ++v) {
      out.print("{} ", v + 1);
      out.coordinates(mesh.vertices[v]);
      out.print("\n");
    }
    out.print("$EndNodes\n$Elements\n{}\n", m);
    // Tags: no physical group, elementary entity 1.
    for (std::size_t t = 0; t < m; ++t) {
      const Tet& e = mesh.tets[t];
      out.print("{} 4 2 0 1 {} {} {} {}\n", t + 1, e[0] + 1, e[1] + 1, e[2] + 1, e[3] + 1);
    }
    out.print("$EndElements\n");
    return;
  }
  // One volume entity holding every node and tet.
  Vec3 lo = mesh.vertices[0], hi = mesh.vertices[0];
  for (const Vec3& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  out.print("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n1 ");
  out.coordinates(lo);
  out.print(" ");
  out.coordinates(hi);
  out.print(" 0 0\n$EndEntities\n$Nodes\n1 {} 1 {}\n3 1 0 {}\n", n, n, n);
  for (std::size_t v = 0; v < n; ++v) out.print("{}\n", v + 1);
  for (const Vec3& v : mesh.vertices) {
    out.coordinates(v);
    out.print("\n");
  }
  out.print("$EndNodes\n$Elements\n1 {} 1 {}\n3 1 4 {}\n", m, m, m);
  for (std::size_t t = 0; t < m; ++t) {
    const Tet& e = mesh.tets[t];
    out.print("{} {} {} {} {}\n", t + 1, e[0] + 1, e[1] + 1, e[2] + 1, e[3] + 1);
  }
  out.print("$EndElements\n");
}

}  // namespace vrd::io
