#pragma once
// Render-mesh embedding: a fine render surface whose vertices follow a coarse deforming tet mesh.
// Each render vertex is bound at rest to one tet by barycentric coordinates; per frame every tet's
// affine map moves the vertices bound to it and its cofactor matrix turns their normals.

#include <array>
#include <concepts>
#include <cstddef>
#include <span>
#include <vector>

#include "vrdeform/mesh/tet_mesh.h"
#include "vrdeform/mesh/vertex_normals.h"

namespace vrd {

/// Where one render vertex sits: its tet and its barycentric coordinates in it (weights of the tet's
/// vertices 0..3, summing to 1; some are negative for a vertex outside the tet mesh).
struct VertexBinding {
  Index tet = 0;
  std::array<float, 4> weights{};
};

namespace detail {
/// Eight consecutive render vertices of an Embedding, one lane each: barycentric b1..b3 and the
/// rest normal premultiplied by cof(Dm^-1), so that cof(Ds) m is the deformed normal.
struct alignas(32) EmbeddingBlock {
  static constexpr int kLanes = 8;
  float b[3][kLanes];
  float m[3][kLanes];
};
}  // namespace detail

/// Which SIMD kernel Embedding::update runs.
enum class EmbeddingSimd {
  best,  ///< AVX2 + FMA (8 lanes) when the CPU has them, else SSE (one vertex at a time off x86-64)
  sse,   ///< SSE (4 lanes) on every x86-64 (one vertex at a time elsewhere)
};

/// Binds each vertex of a render surface to the tet containing it (or, for vertices outside the
/// tet mesh, the nearest tet) by barycentric coordinates computed in double at rest.
class Embedding {
 public:
  Embedding() = default;

  /// Throws vrd::Error for an invalid tet mesh or render surface (validateTetMesh, validateTriMesh).
  static Embedding bind(const TetMesh& restTets, const TriMesh& render);

  /// Positions and unit normals of every render vertex (render-mesh order) for the deformed tet
  /// vertices (tet-mesh order). outNormals may be empty to skip normals. Vertices in no triangle get
  /// a zero normal; otherwise the output is finite for finite input, even for flat or inverted tets.
  /// Throws vrd::Error for spans of the wrong size. Fastest when consecutive render vertices tend
  /// to share a tet (any spatially coherent vertex order).
  void update(std::span<const Vec3> tetPositions, std::span<Vec3> outPositions, std::span<Vec3> outNormals) const;

  /// The same from an array of structs with a Vec3 member `pos`, e.g. a body's slice of the
  /// solver's particles (std::span<const vrd::Point>), read in place.
  template <typename P>
  requires std::same_as<decltype(P::pos), Vec3>
  void update(std::span<const P> tetPoints, std::span<Vec3> outPositions, std::span<Vec3> outNormals) const {
    updateStrided(tetPoints.empty() ? nullptr : &tetPoints.front().pos, sizeof(P), tetPoints.size(), outPositions,
                  outNormals);
  }

  void setSimd(EmbeddingSimd simd) { simd_ = simd; }
  /// Whether update runs the 8-lane AVX2 kernel (setSimd(best) on a CPU that has AVX2 and FMA).
  bool usesAvx2() const;

  std::size_t vertexCount() const { return vertexCount_; }
  std::size_t tetVertexCount() const { return tetVertexCount_; }
  /// Render vertices inside no tet, bound to the nearest one (their coordinates extrapolate).
  std::size_t outsideCount() const { return outsideCount_; }
  /// Largest rest distance from an outside vertex to its tet (0 if there is none).
  double maxOutsideDistance() const { return maxOutsideDistance_; }
  /// Share of 8-vertex blocks whose vertices are bound to more than one tet (each distinct tet
  /// costs such a block one more pass).
  double mixedBlockShare() const;
  /// The tet and barycentric coordinates of render vertex v (e.g. to carry other attributes).
  VertexBinding binding(std::size_t v) const;

 private:
  using Block = detail::EmbeddingBlock;
  static constexpr int kBlock = Block::kLanes;

  void updateStrided(const Vec3* first, std::size_t strideBytes, std::size_t count, std::span<Vec3> outPositions,
                     std::span<Vec3> outNormals) const;

  // "Used tets" are the tets that hold at least one render vertex, numbered in order of first use.
  std::vector<Tet> usedTets_;               ///< their tet-mesh vertices
  std::vector<Index> usedTetIndex_;         ///< their index in the tet mesh
  std::vector<Mat3T<double>> restInverse_;  ///< their Dm^-1, for the flat-tet path
  std::vector<Block> blocks_;
  std::vector<Index> blockTet_;   ///< used tet of all of a block's vertices, or kMixed
  std::vector<Index> vertexTet_;  ///< used tet of each vertex, padded to whole blocks
  std::size_t vertexCount_ = 0;
  std::size_t tetVertexCount_ = 0;
  std::size_t outsideCount_ = 0;
  double maxOutsideDistance_ = 0;
  EmbeddingSimd simd_ = EmbeddingSimd::best;
};

}  // namespace vrd
