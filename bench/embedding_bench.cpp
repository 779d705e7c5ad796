// Render-mesh embedding benchmarks (Google Benchmark): a 500,002-vertex sphere embedded in a box of
// 1,512 tets that rotates and squashes from frame to frame.
//  - Update/...: Embedding::update (per-tet affine map and cofactor, 8-vertex blocks in render
//    order; avx2:1 the AVX2+FMA kernel where the CPU has it, avx2:0 the SSE one) against the
//    baseline in the same run: per vertex the sum of its tet's four weighted positions, normals
//    recomputed from the deformed render triangles (computeVertexNormals). normals:0 times
//    positions only. shuffled:1 numbers the render vertices at random: nearly every block then
//    spans several tets (mixed_blocks), the worst case for the embedding.
//  - Bind: locating all 500,002 vertices at rest.
// Target (issue): 500,000 vertices, positions + normals, <= 2 ms on one core.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <random>

#include "vrdeform/mesh/embedding.h"
#include "vrdeform/mesh/primitives.h"

namespace vrd {
namespace {

TriMesh shuffledVertices(const TriMesh& mesh) {
  std::vector<Index> newIndex(mesh.vertices.size());
  std::iota(newIndex.begin(), newIndex.end(), Index{0});
  std::shuffle(newIndex.begin(), newIndex.end(), std::mt19937(5));
  TriMesh out;
  out.vertices.resize(mesh.vertices.size());
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) out.vertices[newIndex[v]] = mesh.vertices[v];
  for (const Triangle& t : mesh.triangles) out.triangles.push_back({newIndex[t[0]], newIndex[t[1]], newIndex[t[2]]});
  return out;
}

struct Scene {
  TetMesh tets = makeBoxTets(Vec3(-1.05f, -1.05f, -1.05f), Vec3(2.1f, 2.1f, 2.1f), 7, 6, 6);  // 1,512 tets
  TriMesh render;
  Embedding embedding;
  std::vector<std::vector<Vec3>> frames;  // deformed tet vertices, cycled

  explicit Scene(bool shuffled) {
    const TriMesh sphere = makeUvSphere(Vec3::Zero(), 1.0f, 501, 1000);  // 500,002 vertices
    render = shuffled ? shuffledVertices(sphere) : sphere;
    embedding = Embedding::bind(tets, render);
    // Rotate about a tilted axis, squash along y by up to 20% (bulging the others), bend a little.
    for (int f = 0; f < 16; ++f) {
      const double phase = 2 * std::numbers::pi * f / 16, squash = 1 - 0.2 * std::sin(phase) * std::sin(phase);
      const Mat3T<double> a = Eigen::AngleAxisd(0.3 * phase, Vec3T<double>(0.2, 1, 0.3).normalized()).matrix() *
                              Vec3T<double>(1 / std::sqrt(squash), squash, 1 / std::sqrt(squash)).asDiagonal();
      std::vector<Vec3> x;
      for (const Vec3& p : tets.vertices) {
        Vec3T<double> q = p.cast<double>();
        q.y() += 0.1 * std::sin(phase) * q.x() * q.x();
        x.push_back((a * q).cast<float>());
      }
      frames.push_back(std::move(x));
    }
  }
  static const Scene& get(bool shuffled) {
    static const Scene ordered(false), random(true);
    return shuffled ? random : ordered;
  }
};

void setCounters(benchmark::State& state, const Scene& scene, const char* label) {
  state.counters["vertices"] = double(scene.render.vertices.size());
  state.counters["tets"] = double(scene.tets.tets.size());
  state.counters["vertices/s"] = benchmark::Counter(double(scene.render.vertices.size()) * double(state.iterations()),
                                                    benchmark::Counter::kIsRate);
  state.SetLabel(label);
}

void Update(benchmark::State& state) {
  const bool normals = state.range(0) != 0, shuffled = state.range(1) != 0;
  const Scene& scene = Scene::get(shuffled);
  Embedding embedding = scene.embedding;
  embedding.setSimd(state.range(2) != 0 ? EmbeddingSimd::best : EmbeddingSimd::sse);
  std::vector<Vec3> positions(scene.render.vertices.size()), outNormals(normals ? positions.size() : 0);
  std::size_t frame = 0;
  for (auto _ : state) {
    embedding.update(scene.frames[frame++ % scene.frames.size()], positions, outNormals);
    benchmark::DoNotOptimize(positions.data());
    benchmark::DoNotOptimize(outNormals.data());
    benchmark::ClobberMemory();
  }
  setCounters(state, scene, embedding.usesAvx2() ? "embedding, AVX2+FMA" : "embedding, SSE");
  state.counters["mixed_blocks"] = embedding.mixedBlockShare();
}
BENCHMARK(Update)
    ->ArgNames({"normals", "shuffled", "avx2"})
    ->ArgsProduct({{1, 0}, {0, 1}, {1, 0}})
    ->Unit(benchmark::kMillisecond);

void Baseline(benchmark::State& state) {
  const bool normals = state.range(0) != 0, shuffled = state.range(1) != 0;
  const Scene& scene = Scene::get(shuffled);
  const std::size_t n = scene.render.vertices.size();
  std::vector<VertexBinding> bindings(n);
  for (std::size_t v = 0; v < n; ++v) bindings[v] = scene.embedding.binding(v);
  std::vector<Vec3> positions(n), outNormals(n);
  std::size_t frame = 0;
  for (auto _ : state) {
    const std::vector<Vec3>& x = scene.frames[frame++ % scene.frames.size()];
    for (std::size_t v = 0; v < n; ++v) {
      const Tet& tet = scene.tets.tets[bindings[v].tet];
      const auto& w = bindings[v].weights;
      positions[v] = w[0] * x[tet[0]] + w[1] * x[tet[1]] + w[2] * x[tet[2]] + w[3] * x[tet[3]];
    }
    if (normals) computeVertexNormals(scene.render.triangles, positions, outNormals);
    benchmark::DoNotOptimize(positions.data());
    benchmark::DoNotOptimize(outNormals.data());
    benchmark::ClobberMemory();
  }
  setCounters(state, scene, "baseline (barycentric sum, normals from triangles)");
}
BENCHMARK(Baseline)->ArgNames({"normals", "shuffled"})->ArgsProduct({{1, 0}, {0, 1}})->Unit(benchmark::kMillisecond);

void Bind(benchmark::State& state) {
  const Scene& scene = Scene::get(false);
  for (auto _ : state) benchmark::DoNotOptimize(Embedding::bind(scene.tets, scene.render));
  setCounters(state, scene, "locate every vertex at rest");
}
BENCHMARK(Bind)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace vrd

BENCHMARK_MAIN();
