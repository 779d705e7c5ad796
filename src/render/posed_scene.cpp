#include "vrdeform/render/posed_scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "vrdeform/error.h"

namespace vrd {

std::string_view colorMapName(ColorMap map) {
  switch (map) {
    case ColorMap::Strain:
      return "strain";
    case ColorMap::VolumeChange:
      return "volume";
    case ColorMap::ConstraintForce:
      return "force";
    case ColorMap::None:
      break;
  }
  return "none";
}

float defaultColorRange(ColorMap map, const Snapshot& settled) {
  if (map != ColorMap::ConstraintForce) return 0.02f;
  std::vector<float> load = settled.constraintForce;
  if (load.empty()) return 1.0f;
  std::nth_element(load.begin(), load.begin() + load.size() / 2, load.end());
  const float median = load[load.size() / 2];
  return median > 0.0f ? 3.0f * median : 1.0f;
}

std::optional<ColorMap> parseColorMap(std::string_view name) {
  for (ColorMap m : {ColorMap::None, ColorMap::Strain, ColorMap::VolumeChange, ColorMap::ConstraintForce})
    if (colorMapName(m) == name) return m;
  return std::nullopt;
}

PosedScene::PosedScene(const BuiltScene& scene) : meshes_(viewMeshes(scene)), colliders_(scene.spec.colliders) {
  for (const SceneBody& b : scene.bodies) {
    const std::vector<Vec3>& rest = b.mesh.tets.vertices;
    particles_ += rest.size();
    BodyRest r;
    r.tets = b.mesh.tets.tets;
    r.edgeCount.assign(rest.size(), 0.0f);
    r.tetCount.assign(rest.size(), 0.0f);
    r.particleValues.assign(rest.size(), 0.0f);
    // The edges of the tets (soft) or triangles (cloth), each once.
    std::vector<std::pair<Index, Index>> pairs;
    const auto add = [&](Index a, Index b) { pairs.emplace_back(std::min(a, b), std::max(a, b)); };
    for (const Tet& t : r.tets)
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) add(t[i], t[j]);
    if (b.kind == BodyKind::Cloth)
      for (const Triangle& t : b.mesh.surface.triangles)
        for (int i = 0; i < 3; ++i) add(t[i], t[(i + 1) % 3]);
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    for (const auto& [a, c] : pairs) {
      r.edges.push_back({a, c, (rest[a] - rest[c]).norm()});
      r.edgeCount[a] += 1.0f;
      r.edgeCount[c] += 1.0f;
    }
    for (const Tet& t : r.tets) {
      const float v = signedTetVolume(rest[t[0]], rest[t[1]], rest[t[2]], rest[t[3]]);
      r.restVolume.push_back(v);
      r.totalRestVolume += v;
      for (Index i : t) r.tetCount[i] += 1.0f;
    }
    bodies_.push_back(std::move(r));
    for (const Vec3& p : rest) bounds_.extend(p);
  }
  posed_.resize(meshes_.size());
  for (std::size_t i = 0; i < meshes_.size(); ++i) {
    const std::size_t n = meshes_[i].vertexCount();
    posed_[i].positions.assign(n, Vec3::Zero());
    posed_[i].normals.assign(n, Vec3::UnitY());
    posed_[i].values.assign(n, 0.0f);
  }
}

void PosedScene::particleValues(BodyRest& body, std::span<const Vec3> x, std::span<const float> force,
                                ColorMap map) const {
  std::vector<float>& out = body.particleValues;
  std::fill(out.begin(), out.end(), 0.0f);
  if (map == ColorMap::Strain) {
    for (const Edge& e : body.edges) {
      const float strain = e.restLength > 0.0f ? (x[e.a] - x[e.b]).norm() / e.restLength - 1.0f : 0.0f;
      out[e.a] += strain;
      out[e.b] += strain;
    }
    for (std::size_t i = 0; i < out.size(); ++i)
      if (body.edgeCount[i] > 0.0f) out[i] /= body.edgeCount[i];
  } else if (map == ColorMap::VolumeChange) {
    for (std::size_t j = 0; j < body.tets.size(); ++j) {
      const Tet& t = body.tets[j];
      const float change = signedTetVolume(x[t[0]], x[t[1]], x[t[2]], x[t[3]]) / body.restVolume[j] - 1.0f;
      for (Index i : t) out[i] += change;
    }
    for (std::size_t i = 0; i < out.size(); ++i)
      if (body.tetCount[i] > 0.0f) out[i] /= body.tetCount[i];
  } else if (map == ColorMap::ConstraintForce && !force.empty()) {
    std::copy(force.begin(), force.end(), out.begin());
  }
}

void PosedScene::pose(const Snapshot& snapshot, ColorMap map) {
  if (snapshot.positions.size() != particles_ || snapshot.bodyFirst.size() != bodies_.size() ||
      (!snapshot.constraintForce.empty() && snapshot.constraintForce.size() != particles_))
    throw Error(fmt::format("posed scene: a snapshot of {} particles in {} bodies, the scene has {} in {}",
                            snapshot.positions.size(), snapshot.bodyFirst.size(), particles_, bodies_.size()));
  bounds_.setEmpty();
  for (std::size_t i = 0; i < meshes_.size(); ++i) {
    const ViewMesh& m = meshes_[i];
    BodyRest& body = bodies_[m.body];
    const std::span<const Vec3> x = bodyPositions(snapshot, m.body);
    if (x.size() != body.particleValues.size())
      throw Error(fmt::format("posed scene: body {} has {} particles in the snapshot, {} in the scene", m.name,
                              x.size(), body.particleValues.size()));
    Posed& p = posed_[i];
    updateViewMesh(m, x, p.positions, p.normals);
    for (const Vec3& v : p.positions) bounds_.extend(v);

    double volume = 0.0;
    for (const Tet& t : body.tets) volume += signedTetVolume(x[t[0]], x[t[1]], x[t[2]], x[t[3]]);
    body.volumeLoss = body.totalRestVolume > 0.0 ? (body.totalRestVolume - volume) / body.totalRestVolume : 0.0;

    const std::span<const float> force =
        snapshot.constraintForce.empty()
            ? std::span<const float>()
            : std::span(snapshot.constraintForce).subspan(snapshot.bodyFirst[m.body], x.size());
    particleValues(body, x, force, map);
    const std::vector<float>& values = body.particleValues;
    if (map == ColorMap::None) {
      std::fill(p.values.begin(), p.values.end(), 0.0f);
    } else if (m.embedding) {  // a render vertex takes its tet's particle values, interpolated
      for (std::size_t v = 0; v < p.values.size(); ++v) {
        const VertexBinding b = m.embedding->binding(v);
        const Tet& t = body.tets[b.tet];
        float value = 0.0f;
        for (int k = 0; k < 4; ++k) value += b.weights[k] * values[t[k]];
        p.values[v] = value;
      }
    } else {
      for (std::size_t v = 0; v < p.values.size(); ++v) p.values[v] = values[m.particles[v]];
    }
  }
}

std::optional<RayHit> PosedScene::pick(const Ray& ray) const {
  std::optional<RayHit> best;
  float nearest = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < meshes_.size(); ++i) {
    const std::vector<Vec3>& x = posed_[i].positions;
    for (const Triangle& t : meshes_[i].triangles) {
      // Moller-Trumbore: solve origin + s dir = a + u (b - a) + v (c - a).
      const Vec3 e1 = x[t[1]] - x[t[0]], e2 = x[t[2]] - x[t[0]];
      const Vec3 p = ray.direction.cross(e2);
      const float det = e1.dot(p);
      if (std::abs(det) < 1e-12f) continue;
      const Vec3 s = ray.origin - x[t[0]];
      const float u = s.dot(p) / det;
      if (u < 0.0f || u > 1.0f) continue;
      const Vec3 q = s.cross(e1);
      const float v = ray.direction.dot(q) / det;
      if (v < 0.0f || u + v > 1.0f) continue;
      const float d = e2.dot(q) / det;
      if (d <= 0.0f || d >= nearest) continue;
      nearest = d;
      Vec3 n = e1.cross(e2).normalized();
      if (n.dot(ray.direction) > 0.0f) n = -n;
      best = RayHit{d, ray.origin + d * ray.direction, n, meshes_[i].body};
    }
  }
  return best;
}

}  // namespace vrd
