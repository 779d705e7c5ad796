#include "vrdeform/mesh/embedding.h"

#include <fmt/format.h>

#if defined(__x86_64__) || defined(__i386__)
#define VRD_EMBEDDING_X86 1  // the SSE and AVX2 kernels below; elsewhere, one vertex at a time
#include <immintrin.h>
#endif

#include <algorithm>
#include <cstring>
#include <limits>

#include "vrdeform/error.h"
#include "vrdeform/mesh/bvh.h"

namespace vrd {
namespace {

using Mat3d = Mat3T<double>;

constexpr double kInsideTolerance = 1e-9;  // smallest barycentric coordinate that still counts as inside
// A deformed tet whose edge matrix D has |det D| / (|D|_F |cof D|_F) (at most 1 / its condition
// number) below this takes the double-precision path; above it, float cof(D) m cannot vanish.
constexpr double kWellShaped = 1e-4;
// On that path a mapped normal shorter than this (relative) is rounding noise of the float m.
constexpr double kNoise = 1e-6;
constexpr Index kMixed = ~Index{0};  // blockTet_ of a block whose vertices lie in several tets
constexpr Index kUnused = ~Index{0};
static_assert(sizeof(Vec3) == 3 * sizeof(float), "output spans are written as packed float triples");

/// Columns e2 x e3, e3 x e1, e1 x e2 of the edge matrix (e1 e2 e3): det(D) D^-T without dividing.
Mat3d cofactor(const Mat3d& d) {
  Mat3d c;
  c.col(0) = d.col(1).cross(d.col(2));
  c.col(1) = d.col(2).cross(d.col(0));
  c.col(2) = d.col(0).cross(d.col(1));
  return c;
}

double segmentDistanceSq(const Vec3d& p, const Vec3d& a, const Vec3d& b) {
  const Vec3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - a - t * ab).squaredNorm();
}

double triangleDistanceSq(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  const Vec3d n = (b - a).cross(c - a);
  // Over the triangle (inside all three edge planes) the nearest point is the projection.
  if ((b - a).cross(p - a).dot(n) >= 0 && (c - b).cross(p - b).dot(n) >= 0 && (a - c).cross(p - c).dot(n) >= 0) {
    const double h = (p - a).dot(n);
    return h * h / n.squaredNorm();
  }
  return std::min({segmentDistanceSq(p, a, b), segmentDistanceSq(p, b, c), segmentDistanceSq(p, c, a)});
}

/// The rest tets in double: corners and Dm^-1.
struct RestTets {
  std::vector<std::array<Vec3d, 4>> corners;
  std::vector<Mat3d> inverse;

  explicit RestTets(const TetMesh& mesh) : corners(mesh.tets.size()), inverse(mesh.tets.size()) {
    for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
      for (int k = 0; k < 4; ++k) corners[t][k] = mesh.vertices[mesh.tets[t][k]].cast<double>();
      inverse[t] = edges(t).inverse();
    }
  }
  Mat3d edges(std::size_t t) const {
    Mat3d dm;
    for (int k = 0; k < 3; ++k) dm.col(k) = corners[t][k + 1] - corners[t][0];
    return dm;
  }
  /// Barycentric coordinates of p for vertices 1..3; vertex 0 gets 1 - their sum.
  Vec3d barycentric(std::size_t t, const Vec3d& p) const { return inverse[t] * (p - corners[t][0]); }
  static double minCoordinate(const Vec3d& b) { return std::min(1.0 - b.sum(), b.minCoeff()); }

  /// 0 inside (to the tolerance), else the distance to the nearest face.
  double distanceSq(std::size_t t, const Vec3d& p) const {
    if (minCoordinate(barycentric(t, p)) >= -kInsideTolerance) return 0;
    const auto& c = corners[t];
    return std::min({triangleDistanceSq(p, c[1], c[2], c[3]), triangleDistanceSq(p, c[0], c[3], c[2]),
                     triangleDistanceSq(p, c[0], c[1], c[3]), triangleDistanceSq(p, c[0], c[2], c[1])});
  }
};

/// Unit vector along v, or zero when v is zero (or so small that its length underflows).
template <typename S>
Vec3T<S> normalizedOrZero(const Vec3T<S>& v) {
  const S length = v.norm();
  return length > 0 && std::isfinite(length) ? Vec3T<S>(v / length) : Vec3T<S>::Zero();
}

// ---- Per-frame kernels -------------------------------------------------------------------------
// Every used tet's map as floats: o = x0 (3), D row-major (9), cof(D) / |cof(D)| row-major (9).
// The unit-norm cofactor keeps |cof(D) m| of order 1 whatever the size of the tet.
constexpr int kO = 0, kD = 3, kC = 12;
struct alignas(32) Frame {
  float v[24];
};

// One vertex at a time (CPUs other than x86-64): the lanes' maths, with an exact square root where
// they refine rsqrt.
template <bool Normals>
void updatePortable(std::span<const detail::EmbeddingBlock> blocks, const Index* vertexTet, const Frame* frames,
                    float* outPositions, float* outNormals, std::size_t vertexCount) {
  constexpr std::size_t kLanes = detail::EmbeddingBlock::kLanes;
  for (std::size_t v = 0; v < vertexCount; ++v) {
    const detail::EmbeddingBlock& block = blocks[v / kLanes];
    const std::size_t l = v % kLanes;
    const float* f = frames[vertexTet[v]].v;
    for (int i = 0; i < 3; ++i)
      outPositions[3 * v + i] = f[kO + i] + f[kD + 3 * i] * block.b[0][l] + f[kD + 3 * i + 1] * block.b[1][l] +
                                f[kD + 3 * i + 2] * block.b[2][l];
    if constexpr (Normals) {
      float n[3];
      for (int i = 0; i < 3; ++i)
        n[i] = f[kC + 3 * i] * block.m[0][l] + f[kC + 3 * i + 1] * block.m[1][l] + f[kC + 3 * i + 2] * block.m[2][l];
      const float len2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
      const float r = len2 > 0.0f ? 1.0f / std::sqrt(len2) : 0.0f;  // zero for a loose vertex
      for (int i = 0; i < 3; ++i) outNormals[3 * v + i] = n[i] * r;
    }
  }
}

#ifdef VRD_EMBEDDING_X86
struct SseFrame {  // the same, each value in all four lanes
  __m128 v[21];
};

/// Four vertices' x, y, z lanes -> 12 floats x0 y0 z0 x1 ... z3 at o (unaligned).
inline void storeXyz(__m128 x, __m128 y, __m128 z, float* o) {
  const __m128 xy = _mm_unpacklo_ps(x, y);                                  // x0 y0 x1 y1
  const __m128 zx = _mm_shuffle_ps(z, x, _MM_SHUFFLE(1, 1, 0, 0));          // z0 z0 x1 x1
  const __m128 yz = _mm_shuffle_ps(y, z, _MM_SHUFFLE(1, 1, 1, 1));          // y1 y1 z1 z1
  const __m128 xy2 = _mm_shuffle_ps(x, y, _MM_SHUFFLE(2, 2, 2, 2));         // x2 x2 y2 y2
  const __m128 zx3 = _mm_shuffle_ps(z, x, _MM_SHUFFLE(3, 3, 2, 2));         // z2 z2 x3 x3
  const __m128 yz3 = _mm_shuffle_ps(y, z, _MM_SHUFFLE(3, 3, 3, 3));         // y3 y3 z3 z3
  _mm_storeu_ps(o, _mm_shuffle_ps(xy, zx, _MM_SHUFFLE(2, 0, 1, 0)));        // x0 y0 z0 x1
  _mm_storeu_ps(o + 4, _mm_shuffle_ps(yz, xy2, _MM_SHUFFLE(2, 0, 2, 0)));   // y1 z1 x2 y2
  _mm_storeu_ps(o + 8, _mm_shuffle_ps(zx3, yz3, _MM_SHUFFLE(2, 0, 2, 0)));  // z2 x3 y3 z3
}

inline __m128 blend4(__m128 mask, __m128 a, __m128 b) { return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b)); }

// x = o + D b, n = normalize(C m): four vertices, SSE.
template <bool Normals>
inline void kernel4(const SseFrame& f, const float* b, const float* m, int stride, __m128 (&p)[3], __m128 (&n)[3]) {
  const __m128 b0 = _mm_load_ps(b), b1 = _mm_load_ps(b + stride), b2 = _mm_load_ps(b + 2 * stride);
  for (int i = 0; i < 3; ++i)
    p[i] = _mm_add_ps(_mm_add_ps(f.v[kO + i], _mm_mul_ps(f.v[kD + 3 * i], b0)),
                      _mm_add_ps(_mm_mul_ps(f.v[kD + 3 * i + 1], b1), _mm_mul_ps(f.v[kD + 3 * i + 2], b2)));
  if constexpr (Normals) {
    const __m128 m0 = _mm_load_ps(m), m1 = _mm_load_ps(m + stride), m2 = _mm_load_ps(m + 2 * stride);
    for (int i = 0; i < 3; ++i)
      n[i] = _mm_add_ps(_mm_add_ps(_mm_mul_ps(f.v[kC + 3 * i], m0), _mm_mul_ps(f.v[kC + 3 * i + 1], m1)),
                        _mm_mul_ps(f.v[kC + 3 * i + 2], m2));
    const __m128 len2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(n[0], n[0]), _mm_mul_ps(n[1], n[1])), _mm_mul_ps(n[2], n[2]));
    // rsqrt to 12 bits, one Newton step to ~23; zero for a zero rest normal (a loose vertex).
    __m128 r = _mm_rsqrt_ps(len2);
    r = _mm_mul_ps(r, _mm_sub_ps(_mm_set1_ps(1.5f), _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(0.5f), len2), _mm_mul_ps(r, r))));
    r = _mm_and_ps(r, _mm_cmpgt_ps(len2, _mm_setzero_ps()));
    for (__m128& c : n) c = _mm_mul_ps(c, r);
  }
}

template <bool Normals>
void updateSse(std::span<const detail::EmbeddingBlock> blocks, const Index* blockTet, const Index* vertexTet,
               const SseFrame* frames, float* outPositions, float* outNormals, std::size_t vertexCount) {
  constexpr int kLanes = 4, kStride = detail::EmbeddingBlock::kLanes;
  alignas(16) float bufP[kLanes * 3], bufN[kLanes * 3];
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    for (int h = 0; h < kStride / kLanes; ++h) {
      const std::size_t first = i * kStride + h * kLanes;
      if (first >= vertexCount) break;
      const float* b = blocks[i].b[0] + h * kLanes;
      const float* m = blocks[i].m[0] + h * kLanes;
      __m128 p[3], n[3];
      const Index* tets = vertexTet + first;
      const Index tet = blockTet[i] != kMixed ? blockTet[i] : tets[0];
      kernel4<Normals>(frames[tet], b, m, kStride, p, n);
      if (blockTet[i] == kMixed) {
        // One more pass per further tet among the four lanes, blended in by lane.
        const __m128i laneTets = _mm_loadu_si128(reinterpret_cast<const __m128i*>(tets));
        unsigned left =
            ~unsigned(_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(laneTets, _mm_set1_epi32(int(tet))))));
        left &= (1u << kLanes) - 1;
        while (left) {
          const Index other = tets[__builtin_ctz(left)];
          const __m128 mask = _mm_castsi128_ps(_mm_cmpeq_epi32(laneTets, _mm_set1_epi32(int(other))));
          left &= ~unsigned(_mm_movemask_ps(mask));
          __m128 p2[3], n2[3];
          kernel4<Normals>(frames[other], b, m, kStride, p2, n2);
          for (int c = 0; c < 3; ++c) {
            p[c] = blend4(mask, p2[c], p[c]);
            if constexpr (Normals) n[c] = blend4(mask, n2[c], n[c]);
          }
        }
      }
      const std::size_t count = std::min<std::size_t>(kLanes, vertexCount - first);
      float* op = count == kLanes ? outPositions + 3 * first : bufP;
      float* on = count == kLanes ? outNormals + 3 * first : bufN;
      storeXyz(p[0], p[1], p[2], op);
      if constexpr (Normals) storeXyz(n[0], n[1], n[2], on);
      if (count < kLanes) {
        std::memcpy(outPositions + 3 * first, bufP, count * 3 * sizeof(float));
        if constexpr (Normals) std::memcpy(outNormals + 3 * first, bufN, count * 3 * sizeof(float));
      }
    }
  }
}

#define VRD_AVX2 __attribute__((target("avx2,fma")))

template <bool Normals>
VRD_AVX2 inline void kernel8(const Frame& f, const float* b, const float* m, __m256 (&p)[3], __m256 (&n)[3]) {
  constexpr int kStride = detail::EmbeddingBlock::kLanes;
  const __m256 b0 = _mm256_load_ps(b), b1 = _mm256_load_ps(b + kStride), b2 = _mm256_load_ps(b + 2 * kStride);
  for (int i = 0; i < 3; ++i) {
    const float* d = f.v + kD + 3 * i;
    p[i] = _mm256_fmadd_ps(
        _mm256_broadcast_ss(d + 2), b2,
        _mm256_fmadd_ps(_mm256_broadcast_ss(d + 1), b1,
                        _mm256_fmadd_ps(_mm256_broadcast_ss(d), b0, _mm256_broadcast_ss(f.v + kO + i))));
  }
  if constexpr (Normals) {
    const __m256 m0 = _mm256_load_ps(m), m1 = _mm256_load_ps(m + kStride), m2 = _mm256_load_ps(m + 2 * kStride);
    for (int i = 0; i < 3; ++i) {
      const float* c = f.v + kC + 3 * i;
      n[i] =
          _mm256_fmadd_ps(_mm256_broadcast_ss(c + 2), m2,
                          _mm256_fmadd_ps(_mm256_broadcast_ss(c + 1), m1, _mm256_mul_ps(_mm256_broadcast_ss(c), m0)));
    }
    const __m256 len2 = _mm256_fmadd_ps(n[2], n[2], _mm256_fmadd_ps(n[1], n[1], _mm256_mul_ps(n[0], n[0])));
    __m256 r = _mm256_rsqrt_ps(len2);
    r = _mm256_mul_ps(
        r, _mm256_fnmadd_ps(_mm256_mul_ps(_mm256_set1_ps(0.5f), len2), _mm256_mul_ps(r, r), _mm256_set1_ps(1.5f)));
    r = _mm256_and_ps(r, _mm256_cmp_ps(len2, _mm256_setzero_ps(), _CMP_GT_OQ));
    for (__m256& c : n) c = _mm256_mul_ps(c, r);
  }
}

VRD_AVX2 inline void storeXyz8(__m256 x, __m256 y, __m256 z, float* o) {
  storeXyz(_mm256_castps256_ps128(x), _mm256_castps256_ps128(y), _mm256_castps256_ps128(z), o);
  storeXyz(_mm256_extractf128_ps(x, 1), _mm256_extractf128_ps(y, 1), _mm256_extractf128_ps(z, 1), o + 12);
}

template <bool Normals>
VRD_AVX2 void updateAvx2(std::span<const detail::EmbeddingBlock> blocks, const Index* blockTet, const Index* vertexTet,
                         const Frame* frames, float* outPositions, float* outNormals, std::size_t vertexCount) {
  constexpr int kLanes = detail::EmbeddingBlock::kLanes;
  alignas(32) float bufP[kLanes * 3], bufN[kLanes * 3];
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const std::size_t first = i * kLanes;
    __m256 p[3], n[3];
    const Index* tets = vertexTet + first;
    const Index tet = blockTet[i] != kMixed ? blockTet[i] : tets[0];
    kernel8<Normals>(frames[tet], blocks[i].b[0], blocks[i].m[0], p, n);
    if (blockTet[i] == kMixed) {
      const __m256i laneTets = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(tets));
      unsigned left =
          ~unsigned(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(laneTets, _mm256_set1_epi32(int(tet))))));
      left &= (1u << kLanes) - 1;
      while (left) {
        const Index other = tets[__builtin_ctz(left)];
        const __m256 mask = _mm256_castsi256_ps(_mm256_cmpeq_epi32(laneTets, _mm256_set1_epi32(int(other))));
        left &= ~unsigned(_mm256_movemask_ps(mask));
        __m256 p2[3], n2[3];
        kernel8<Normals>(frames[other], blocks[i].b[0], blocks[i].m[0], p2, n2);
        for (int c = 0; c < 3; ++c) {
          p[c] = _mm256_blendv_ps(p[c], p2[c], mask);
          if constexpr (Normals) n[c] = _mm256_blendv_ps(n[c], n2[c], mask);
        }
      }
    }
    const std::size_t count = std::min<std::size_t>(kLanes, vertexCount - first);
    float* op = count == kLanes ? outPositions + 3 * first : bufP;
    float* on = count == kLanes ? outNormals + 3 * first : bufN;
    storeXyz8(p[0], p[1], p[2], op);
    if constexpr (Normals) storeXyz8(n[0], n[1], n[2], on);
    if (count < kLanes) {
      std::memcpy(outPositions + 3 * first, bufP, count * 3 * sizeof(float));
      if constexpr (Normals) std::memcpy(outNormals + 3 * first, bufN, count * 3 * sizeof(float));
    }
  }
}

bool cpuHasAvx2() {
  static const bool has = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  }();
  return has;
}
#else
bool cpuHasAvx2() { return false; }
#endif

}  // namespace

Embedding Embedding::bind(const TetMesh& restTets, const TriMesh& render) {
  validateTetMesh(restTets);
  validateTriMesh(render);
  if (render.vertices.size() >= std::numeric_limits<Index>::max() / 2)
    throw Error(fmt::format("render mesh has {} vertices, too many to embed", render.vertices.size()));

  const RestTets rest(restTets);
  std::vector<Box3d> boxes(restTets.tets.size());
  for (std::size_t t = 0; t < boxes.size(); ++t) boxes[t] = elementBox(restTets.vertices, restTets.tets[t]);
  const Bvh bvh(boxes);
  std::vector<Vec3> normals(render.vertices.size());
  computeVertexNormals(render.triangles, render.vertices, normals);

  Embedding e;
  const std::size_t n = render.vertices.size();
  e.vertexCount_ = n;
  e.tetVertexCount_ = restTets.vertices.size();
  e.blocks_.assign((n + kBlock - 1) / kBlock, Block{});
  e.blockTet_.assign(e.blocks_.size(), kMixed);
  e.vertexTet_.assign(e.blocks_.size() * kBlock, 0);
  std::vector<Index> used(restTets.tets.size(), kUnused);  // tet -> used tet

  for (std::size_t v = 0; v < n; ++v) {
    // The containing tet that holds the vertex deepest, else the nearest tet.
    const Vec3d p = render.vertices[v].cast<double>();
    Index tet = 0;
    double deepest = -std::numeric_limits<double>::infinity();
    bvh.overlapping(Box3d(p, p), [&](Index t) {
      const double m = RestTets::minCoordinate(rest.barycentric(t, p));
      if (m > deepest) deepest = m, tet = t;
    });
    if (deepest < -kInsideTolerance) {
      const auto [t, distanceSq] = bvh.nearestTo(p, [&](Index t) { return rest.distanceSq(t, p); });
      tet = t;
      ++e.outsideCount_;
      e.maxOutsideDistance_ = std::max(e.maxOutsideDistance_, std::sqrt(distanceSq));
    }
    if (used[tet] == kUnused) {
      used[tet] = static_cast<Index>(e.usedTets_.size());
      e.usedTets_.push_back(restTets.tets[tet]);
      e.usedTetIndex_.push_back(tet);
      e.restInverse_.push_back(rest.inverse[tet]);
    }
    e.vertexTet_[v] = used[tet];

    // cof(F) n = cof(Ds) cof(Dm^-1) n, and cof(Dm^-1) n is Dm^T n times det(Dm^-1) > 0.
    const Vec3d b = rest.barycentric(tet, p);
    const Vec3d m = normalizedOrZero<double>(rest.edges(tet).transpose() * normals[v].cast<double>());
    Block& block = e.blocks_[v / kBlock];
    for (int k = 0; k < 3; ++k) {
      block.b[k][v % kBlock] = static_cast<float>(b[k]);
      block.m[k][v % kBlock] = static_cast<float>(m[k]);
    }
  }
  // Padding lanes of the last block repeat its first vertex's tet (their output is dropped).
  for (std::size_t v = n; v < e.vertexTet_.size(); ++v) e.vertexTet_[v] = e.vertexTet_[v - v % kBlock];
  for (std::size_t i = 0; i < e.blocks_.size(); ++i) {
    const auto lanes = std::span(e.vertexTet_).subspan(i * kBlock, kBlock);
    if (std::all_of(lanes.begin(), lanes.end(), [&](Index t) { return t == lanes[0]; })) e.blockTet_[i] = lanes[0];
  }
  return e;
}

bool Embedding::usesAvx2() const { return simd_ == EmbeddingSimd::best && cpuHasAvx2(); }

double Embedding::mixedBlockShare() const {
  if (blocks_.empty()) return 0;
  return double(std::count(blockTet_.begin(), blockTet_.end(), kMixed)) / double(blocks_.size());
}

VertexBinding Embedding::binding(std::size_t v) const {
  if (v >= vertexCount_) throw Error(fmt::format("render vertex {} out of range ({} vertices)", v, vertexCount_));
  const Block& block = blocks_[v / kBlock];
  VertexBinding b;
  b.tet = usedTetIndex_[vertexTet_[v]];
  for (int k = 0; k < 3; ++k) b.weights[k + 1] = block.b[k][v % kBlock];
  b.weights[0] = 1.0f - b.weights[1] - b.weights[2] - b.weights[3];
  return b;
}

void Embedding::update(std::span<const Vec3> tetPositions, std::span<Vec3> outPositions,
                       std::span<Vec3> outNormals) const {
  updateStrided(tetPositions.data(), sizeof(Vec3), tetPositions.size(), outPositions, outNormals);
}

void Embedding::updateStrided(const Vec3* first, std::size_t strideBytes, std::size_t count,
                              std::span<Vec3> outPositions, std::span<Vec3> outNormals) const {
  if (count != tetVertexCount_)
    throw Error(fmt::format("{} tet-vertex positions given, the embedding's tet mesh has {}", count, tetVertexCount_));
  if (outPositions.size() != vertexCount_)
    throw Error(
        fmt::format("room for {} render positions, the embedding has {} vertices", outPositions.size(), vertexCount_));
  if (!outNormals.empty() && outNormals.size() != vertexCount_)
    throw Error(
        fmt::format("room for {} render normals, the embedding has {} vertices", outNormals.size(), vertexCount_));
  if (vertexCount_ == 0) return;  // not bound
  const bool normals = !outNormals.empty();
  const auto* base = reinterpret_cast<const unsigned char*>(first);
  auto position = [&](Index i) { return reinterpret_cast<const Vec3*>(base + i * strideBytes)->cast<double>(); };

  // Every used tet's map in double, rounded to float once. Flat tets get cof = 0 here (zero
  // normals) and are redone in double below.
  std::vector<Frame> frames(usedTets_.size());
  std::vector<char> flat(usedTets_.size(), 0);
  bool anyFlat = false;
  for (std::size_t t = 0; t < usedTets_.size(); ++t) {
    const Vec3d x0 = position(usedTets_[t][0]);
    Mat3d d;
    for (int k = 0; k < 3; ++k) d.col(k) = position(usedTets_[t][k + 1]) - x0;
    const Mat3d c = cofactor(d);
    const double det = d.col(0).dot(c.col(0)), cNorm = c.norm();
    flat[t] = !(std::abs(det) >= kWellShaped * d.norm() * cNorm && det != 0);
    anyFlat |= bool(flat[t]);
    const Mat3d cUnit = flat[t] ? Mat3d::Zero() : Mat3d(c / cNorm);
    float* f = frames[t].v;
    for (int i = 0; i < 3; ++i) {
      f[kO + i] = static_cast<float>(x0[i]);
      for (int k = 0; k < 3; ++k) {
        f[kD + 3 * i + k] = static_cast<float>(d(i, k));
        f[kC + 3 * i + k] = static_cast<float>(cUnit(i, k));
      }
    }
  }

  float* outP = outPositions.data()->data();
  float* outN = normals ? outNormals.data()->data() : nullptr;
#ifdef VRD_EMBEDDING_X86
  if (usesAvx2()) {
    (normals ? updateAvx2<true> : updateAvx2<false>)(blocks_, blockTet_.data(), vertexTet_.data(), frames.data(), outP,
                                                     outN, vertexCount_);
  } else {
    std::vector<SseFrame> sse(frames.size());
    for (std::size_t t = 0; t < frames.size(); ++t)
      for (int k = 0; k < 21; ++k) sse[t].v[k] = _mm_set1_ps(frames[t].v[k]);
    (normals ? updateSse<true> : updateSse<false>)(blocks_, blockTet_.data(), vertexTet_.data(), sse.data(), outP, outN,
                                                   vertexCount_);
  }
#else
  (normals ? updatePortable<true> : updatePortable<false>)(blocks_, vertexTet_.data(), frames.data(), outP, outN,
                                                           vertexCount_);
#endif
  if (!anyFlat) return;

  // Flat, collapsed or (for non-finite input) broken tets, per vertex in double: cof(F) n, else
  // F n, else the rest normal, whichever first has a direction.
  for (std::size_t v = 0; v < vertexCount_; ++v) {
    const Index t = vertexTet_[v];
    if (!flat[t]) continue;
    const Vec3d x0 = position(usedTets_[t][0]);
    Mat3d d;
    for (int k = 0; k < 3; ++k) d.col(k) = position(usedTets_[t][k + 1]) - x0;
    const Block& block = blocks_[v / kBlock];
    const Vec3d b(block.b[0][v % kBlock], block.b[1][v % kBlock], block.b[2][v % kBlock]);
    const Vec3d m(block.m[0][v % kBlock], block.m[1][v % kBlock], block.m[2][v % kBlock]);
    outPositions[v] = (x0 + d * b).cast<float>();
    if (!normals) continue;
    const Mat3d c = cofactor(d);
    Vec3d normal = c * m;
    if (!(normal.norm() > kNoise * c.norm())) {
      const Vec3d restNormal = normalizedOrZero<double>(restInverse_[t].transpose() * m);
      const Mat3d f = d * restInverse_[t];
      normal = f * restNormal;
      if (!(normal.norm() > kNoise * f.norm())) normal = restNormal;
    }
    outNormals[v] = normalizedOrZero(normal).cast<float>();
  }
}

}  // namespace vrd
