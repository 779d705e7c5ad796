#pragma once
// The broad phase of body contact: a bounding-volume hierarchy over one body's surface triangles,
// built once on the rest shape and refitted every substep to the triangles' swept boxes, with a
// cone bounding each node's face normals (Volino and Magnenat-Thalmann 1994, Provot 1997).
//
// A node's cone holds the normals of its triangles and of every triangle around their corners, at
// the substep's start and at the prediction. Where one cone narrower than 90 degrees (a direction
// with every normal on its positive side) holds two patches of a closed surface, they cannot touch
// without one being inside the solid already: a vertex resting on a face from outside has a face
// around it turned against that face's normal, and so does an edge. So the self-traversal of a
// closed surface (a soft body's) skips every node and every pair of nodes that one such cone
// holds: a body's smooth stretches cost nothing, and only patches that face each other are tested
// by their boxes. A cloth is two-sided (a fold lays a sheet on a sheet facing the same way), and
// two bodies' surfaces are tested by their boxes alone.
//
// The tree is cut into parts (the subtrees a few levels down) that a team of threads refits and
// traverses side by side: each part, and each pair of parts, is a piece of work of its own.

#include <cstdint>
#include <span>
#include <vector>

#include "vrdeform/math/types.h"
#include "vrdeform/mesh/tet_mesh.h"

namespace vrd {

using Box3f = Eigen::AlignedBox<float, 3>;

/// Whether two boxes overlap: all six comparisons and one branch (the detection's tests pass about
/// half the time, so a branch per axis would often be mispredicted).
inline bool overlap(const Box3f& a, const Box3f& b) {
  const auto below = [](float x, float y) { return int(x <= y); };
  const Vec3 &amin = a.min(), &amax = a.max(), &bmin = b.min(), &bmax = b.max();
  return (below(amin.x(), bmax.x()) & below(bmin.x(), amax.x()) & below(amin.y(), bmax.y()) &
          below(bmin.y(), amax.y()) & below(amin.z(), bmax.z()) & below(bmin.z(), amax.z())) != 0;
}

/// The directions within an angle of the unit `axis`, kept as its cosine and sine (no trigonometry
/// in the tests); the full sphere where no direction has every normal on its positive side, or a
/// normal is not finite.
struct NormalCone {
  Vec3 axis = Vec3::UnitZ();
  float cos = 1.0f, sin = 0.0f;
};
/// The cone about the unit `axis` holding both unit normals of every listed triangle (per triangle:
/// at the substep's start and at the prediction); a normal that is not finite gives the full
/// sphere, a zero one (a degenerate triangle's) a cone of at least 90 degrees.
NormalCone coneAbout(const Vec3& axis, std::span<const Index> triangles, std::span<const Vec3> startNormals,
                     std::span<const Vec3> endNormals);
/// The cone about the unit `axis` holding both cones (each one's angle from the axis plus its own,
/// added as cosines and sines: no trigonometry).
NormalCone enclosing(const Vec3& axis, const NormalCone& a, const NormalCone& b);
/// Whether every normal in the cone is within 90 degrees of its axis.
inline bool facesOneWay(const NormalCone& c) { return c.cos > 0.0f; }
/// Whether one cone that faces one way holds both: each does, and the angle between their axes
/// plus their two angles is under 180 degrees.
inline bool faceOneWay(const NormalCone& a, const NormalCone& b) {
  return a.cos > 0.0f && b.cos > 0.0f && a.axis.dot(b.axis) > a.sin * b.sin - a.cos * b.cos;
}

/// What a refit reads, per triangle: its box, its unit normals at the substep's start and at the
/// prediction (none: every cone the full sphere), and whether a corner moves (none: every one does).
struct SurfaceFrame {
  std::span<const Box3f> boxes;
  std::span<const Vec3> startNormals, endNormals;
  std::span<const std::uint8_t> moving;
};

class SurfaceTree {
 public:
  /// The hierarchy over the triangles, by median splits of their rest centres along the widest
  /// axis. Only the boxes and cones change afterwards.
  void build(std::span<const Triangle> triangles, std::span<const Vec3> rest);

  /// The parts the tree is cut into, and the triangles of each.
  std::size_t parts() const { return parts_.size(); }
  std::span<const Index> partTriangles(std::size_t part) const {
    return std::span(items_).subspan(parts_[part].item, parts_[part].itemEnd - parts_[part].item);
  }

  /// Each node of a part: its box, its normal cone, and whether none of its triangles moves (two
  /// such nodes never touch).
  void refitPart(std::size_t part, const SurfaceFrame& frame);

  /// visit(t, u) once for every pair of two triangles of this surface, t in part i and u in part j
  /// (i == j: both in part i), whose boxes overlap, but those the cones rule out (see above;
  /// `closed`: a closed surface). Parts i <= j together give every pair once.
  template <typename Visit>
  void selfPairs(bool closed, std::size_t i, std::size_t j, Visit&& visit) const {
    if (i == j)
      self(parts_[i].node, closed, visit);
    else
      across(*this, parts_[i].node, parts_[j].node, closed, visit);
  }

  /// visit(t, u) for every triangle t of this surface's part i and u of `other`'s part j whose
  /// boxes overlap.
  template <typename Visit>
  void pairsWith(const SurfaceTree& other, std::size_t i, std::size_t j, Visit&& visit) const {
    across(other, parts_[i].node, other.parts_[j].node, false, visit);
  }

 private:
  struct Node {
    Box3f box;
    NormalCone cone;
    bool still = false;  ///< none of its triangles moves
    Index first = 0;     ///< leaf: first entry in items_; inner node: right child (left is the next node)
    Index count = 0;     ///< triangles in a leaf, 0 for an inner node
  };
  Index build(Index begin, Index end, std::span<const Vec3> centres, int depth);
  struct Part {
    Index node, nodeEnd;  ///< its subtree's nodes, [node, nodeEnd)
    Index item, itemEnd;  ///< and their triangles' entries in items_
  };
  std::vector<Part> parts_;

  template <typename Visit>
  void self(Index n, bool closed, Visit& visit) const {
    const Node& node = nodes_[n];
    if (node.still || (closed && facesOneWay(node.cone))) return;
    if (node.count > 0) {
      for (Index i = node.first; i < node.first + node.count; ++i)
        for (Index j = i + 1; j < node.first + node.count; ++j)
          if (overlap(boxes_[i], boxes_[j])) visit(items_[i], items_[j]);
      return;
    }
    self(n + 1, closed, visit);
    self(node.first, closed, visit);
    across(*this, n + 1, node.first, closed, visit);
  }

  template <typename Visit>
  void across(const SurfaceTree& other, Index n, Index m, bool closed, Visit& visit) const {
    const Node &a = nodes_[n], &b = other.nodes_[m];
    if ((a.still && b.still) || !overlap(a.box, b.box) || (closed && faceOneWay(a.cone, b.cone))) return;
    if (a.count > 0 && b.count > 0) {
      for (Index i = a.first; i < a.first + a.count; ++i)
        for (Index j = b.first; j < b.first + b.count; ++j)
          if (overlap(boxes_[i], other.boxes_[j])) visit(items_[i], other.items_[j]);
    } else if (b.count > 0 || (a.count == 0 && a.box.volume() >= b.box.volume())) {  // open the bigger
      across(other, n + 1, m, closed, visit);
      across(other, a.first, m, closed, visit);
    } else {
      across(other, n, m + 1, closed, visit);
      across(other, n, b.first, closed, visit);
    }
  }

  std::vector<Node> nodes_;
  std::vector<Index> items_;  ///< triangles in leaf order
  std::vector<Box3f> boxes_;  ///< per entry of items_: its triangle's box (leaf order, for the scans)
  /// Per node: the triangles whose normals its cone holds (a leaf's triangles and those around
  /// their corners) are around_[aroundStart_[n], aroundStart_[n + 1]); none for an inner node.
  std::vector<Index> aroundStart_, around_;
};

}  // namespace vrd
