#include "vrdeform/sim/body_model.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include "vrdeform/error.h"
#include "vrdeform/mesh/boundary.h"
#include "vrdeform/sim/constraint_colouring.h"

namespace vrd {
namespace {

bool finiteNonNegative(float v) { return std::isfinite(v) && v >= 0.0f; }

void validateMaterial(const Material& m) {
  const std::pair<const char*, const ConstraintMaterial*> types[] = {
      {"distance", &m.distance},           {"volume", &m.volume},
      {"strainStretch", &m.strainStretch}, {"strainShear", &m.strainShear},
      {"shapeMatching", &m.shapeMatching}, {"bending", &m.bending}};
  for (const auto& [name, c] : types) {
    if (!finiteNonNegative(c->compliance))
      throw Error(fmt::format("material: {} compliance must be finite and >= 0, got {}", name, c->compliance));
    if (!finiteNonNegative(c->damping))
      throw Error(fmt::format("material: {} damping must be finite and >= 0, got {}", name, c->damping));
  }
  const auto positive = [](float v) { return std::isfinite(v) && v > 0.0f; };
  if (!positive(m.density)) throw Error(fmt::format("material: density must be positive, got {}", m.density));
  if (!positive(m.arealDensity))
    throw Error(fmt::format("material: areal density must be positive, got {}", m.arealDensity));
  if (m.particleMass && !positive(*m.particleMass))
    throw Error(fmt::format("material: particle mass must be positive, got {}", *m.particleMass));
  if (m.particleMass && m.elastic)
    throw Error("material: a particle mass cannot go with moduli (their density gives the masses)");
  if (!finiteNonNegative(m.particleRadius))
    throw Error(fmt::format("material: particle radius must be finite and >= 0, got {}", m.particleRadius));
  if (m.elastic) {
    const ElasticModuli& e = *m.elastic;
    if (!(std::isfinite(e.youngsModulus) && e.youngsModulus > 0.0f))
      throw Error(fmt::format("material: Young's modulus must be positive, got {}", e.youngsModulus));
    if (!(e.poissonRatio >= 0.0f && e.poissonRatio < 0.5f))
      throw Error(fmt::format("material: Poisson ratio must be in [0, 0.5), got {}", e.poissonRatio));
    if (!positive(e.density)) throw Error(fmt::format("material: density must be positive, got {}", e.density));
    if (!finiteNonNegative(e.rayleighDamping))
      throw Error(fmt::format("material: Rayleigh damping must be finite and >= 0, got {}", e.rayleighDamping));
  }
}

// The inverse of each particle's lumped mass, or of the fixed particle mass when one is given.
std::vector<float> inverseMasses(const std::vector<double>& lumped, std::optional<float> particleMass) {
  std::vector<float> w(lumped.size());
  for (std::size_t v = 0; v < lumped.size(); ++v) w[v] = particleMass ? 1.0f / *particleMass : float(1.0 / lumped[v]);
  return w;
}

float dampingTime(const ConstraintMaterial& c) { return c.compliance * c.damping; }

ConstraintDamping dampingOf(const Material& m) {
  ConstraintDamping d{dampingTime(m.distance),    dampingTime(m.volume),  dampingTime(m.strainStretch),
                      dampingTime(m.strainShear), dampingTime(m.bending), dampingTime(m.shapeMatching)};
  if (m.elastic) d.distance = d.volume = d.strainStretch = d.strainShear = m.elastic->rayleighDamping;
  return d;
}

using Edge = std::pair<Index, Index>;
Edge sortedEdge(Index a, Index b) { return a < b ? Edge{a, b} : Edge{b, a}; }

template <std::size_t N>
void checkItem(const char* what, std::size_t item, const Index (&idx)[N], std::size_t particles, float compliance) {
  for (std::size_t k = 0; k < N; ++k) {
    if (idx[k] >= particles)
      throw Error(
          fmt::format("{} {} refers to particle {}, but the body has {} particles", what, item, idx[k], particles));
    for (std::size_t j = 0; j < k; ++j)
      if (idx[j] == idx[k]) throw Error(fmt::format("{} {} uses particle {} twice", what, item, idx[k]));
  }
  if (!finiteNonNegative(compliance))
    throw Error(fmt::format("{} {} has compliance {}; it must be finite and >= 0", what, item, compliance));
}

template <typename C>
void checkAll(const char* what, const std::vector<C>& items, std::size_t particles) {
  for (std::size_t c = 0; c < items.size(); ++c) checkItem(what, c, items[c].i, particles, items[c].compliance);
}

template <typename C>
std::vector<std::array<Index, std::extent_v<decltype(C::i)>>> particlesOf(const std::vector<C>& constraints) {
  std::vector<std::array<Index, std::extent_v<decltype(C::i)>>> out(constraints.size());
  for (std::size_t c = 0; c < constraints.size(); ++c)
    std::copy(std::begin(constraints[c].i), std::end(constraints[c].i), out[c].begin());
  return out;
}

template <typename T>
std::vector<T> permuted(const std::vector<T>& items, const std::vector<Index>& order) {
  std::vector<T> out;
  out.reserve(items.size());
  for (Index k : order) out.push_back(items[k]);
  return out;
}

// Constraint arrays at least this long are cut in groups for two threads (twoThreadGroups): a
// group has colours of about a hundred constraints or more, and its thread sweeps them all before
// it waits. Smaller arrays share every colour between the threads.
constexpr std::size_t kMinCutConstraints = 4096;

// The colour order of `constraints`, in groups for two threads when there are enough of them.
template <std::size_t N>
Colouring colourOrder(const std::vector<std::array<Index, N>>& constraints, const std::vector<Vec3>& rest) {
  const bool cut = constraints.size() >= kMinCutConstraints;
  return colourConstraints(constraints, 16, cut ? twoThreadGroups(constraints, rest) : std::vector<std::uint8_t>{});
}

// Puts the distance constraints in colour order.
void colourDistances(BodyModel& model, SolveOrder order) {
  if (order != SolveOrder::Coloured) return;
  const Colouring c = colourOrder(particlesOf(model.distance), model.restPositions);
  model.distance = permuted(model.distance, c.order);
  model.distanceColours = c.colourStart;
  model.distanceGroups = c.groupColours;
}

template <typename C>
void checkColours(const char* what, const std::vector<C>& constraints, const std::vector<std::uint32_t>& colours,
                  const std::vector<std::uint32_t>& groups) {
  if (!constraints.empty() && !coloursIndependent(particlesOf(constraints), colours, groups))
    throw Error(
        fmt::format("{} constraints: two in one colour, or in two groups swept at once, share a particle", what));
}

}  // namespace

void addDistanceConstraint(BodyModel& model, Index a, Index b, float compliance) {
  const float length = (model.restPositions.at(a) - model.restPositions.at(b)).norm();
  model.distance.push_back({{a, b}, length, compliance});
}

ShapeMatchModel makeShapeMatchModel(const BodyModel& model, float compliance) {
  const std::size_t n = model.particleCount();
  ShapeMatchModel sm;
  sm.compliance = compliance;
  sm.mass.resize(n);
  double total = 0.0, kinematicWeight = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    if (model.invMass[i] > 0.0f) total += 1.0 / model.invMass[i];
  // Kinematic particles have no finite mass; weigh them like an average particle.
  kinematicWeight = total > 0.0 ? total / double(n) : 1.0;
  Vec3T<double> centroid = Vec3T<double>::Zero();
  double weightSum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sm.mass[i] = model.invMass[i] > 0.0f ? 1.0f / model.invMass[i] : float(kinematicWeight);
    centroid += double(sm.mass[i]) * model.restPositions[i].cast<double>();
    weightSum += sm.mass[i];
  }
  sm.totalMass = float(weightSum);
  sm.restCentroid = (centroid / weightSum).cast<float>();
  sm.restOffsets.resize(n);
  for (std::size_t i = 0; i < n; ++i) sm.restOffsets[i] = model.restPositions[i] - sm.restCentroid;
  return sm;
}

std::shared_ptr<const BodyModel> makeSoftBody(const TetMesh& mesh, const Material& material,
                                              const ConstraintSet& constraints, SolveOrder order) {
  validateTetMesh(mesh);
  validateMaterial(material);
  auto model = std::make_shared<BodyModel>();
  model->restPositions = mesh.vertices;
  if (order == SolveOrder::Coloured) {
    const Colouring c = colourOrder(mesh.tets, mesh.vertices);
    model->tets = permuted(mesh.tets, c.order);
    model->tetColours = c.colourStart;
    model->tetGroups = c.groupColours;
  } else {
    model->tets = mesh.tets;
  }
  model->surface = boundaryFaces(mesh);  // indexes mesh.vertices = restPositions; by the mesh's tet order
  model->damping = dampingOf(material);
  model->particleRadius = material.particleRadius;

  const std::size_t n = mesh.vertices.size();
  const double density = material.elastic ? material.elastic->density : material.density;
  std::vector<double> restVolume(model->tets.size());
  std::vector<double> lumpedMass(n, 0.0);
  std::vector<char> used(n, 0);
  for (std::size_t t = 0; t < model->tets.size(); ++t) {
    const Tet& tet = model->tets[t];
    const Vec3T<double> p0 = mesh.vertices[tet[0]].cast<double>(), p1 = mesh.vertices[tet[1]].cast<double>(),
                        p2 = mesh.vertices[tet[2]].cast<double>(), p3 = mesh.vertices[tet[3]].cast<double>();
    restVolume[t] = signedTetVolume(p0, p1, p2, p3);
    model->restVolume += restVolume[t];
    for (Index v : tet) {
      used[v] = 1;
      lumpedMass[v] += density * restVolume[t] / 4.0;
    }
  }
  for (std::size_t v = 0; v < n; ++v)
    if (!used[v]) throw Error(fmt::format("vertex {} is not used by any tet; remove unused vertices first", v + 1));
  model->invMass = inverseMasses(lumpedMass, material.particleMass);

  // Elastic mapping (docs/materials.md): strain + volume energies equal linear elasticity at small strain.
  double mu = 0.0, lameLambda = 0.0;
  if (material.elastic) {
    const double E = material.elastic->youngsModulus, nu = material.elastic->poissonRatio;
    mu = E / (2.0 * (1.0 + nu));
    lameLambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  }

  if (constraints.edges) {
    std::map<Edge, double> edgeVolume;  // each tet lends a sixth of its volume to each of its edges
    for (std::size_t t = 0; t < model->tets.size(); ++t)
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b)
          edgeVolume[sortedEdge(model->tets[t][a], model->tets[t][b])] += restVolume[t] / 6.0;
    for (const auto& [edge, volume] : edgeVolume) {
      const double length = (mesh.vertices[edge.first] - mesh.vertices[edge.second]).cast<double>().norm();
      const float compliance = material.elastic ? float(length * length / (material.elastic->youngsModulus * volume))
                                                : material.distance.compliance;
      model->distance.push_back({{edge.first, edge.second}, float(length), compliance});
    }
  }
  if (constraints.volume && !(material.elastic && lameLambda <= 0.0)) {  // nu = 0: no bulk term
    for (std::size_t t = 0; t < model->tets.size(); ++t) {
      const Tet& tet = model->tets[t];
      const float compliance = material.elastic ? float(restVolume[t] / lameLambda) : material.volume.compliance;
      model->volume.push_back({{tet[0], tet[1], tet[2], tet[3]}, float(restVolume[t]), compliance});
    }
  }
  if (constraints.strain) {
    for (std::size_t t = 0; t < model->tets.size(); ++t) {
      const Tet& tet = model->tets[t];
      Mat3T<double> rest;
      const Vec3T<double> p0 = mesh.vertices[tet[0]].cast<double>();
      for (int k = 0; k < 3; ++k) rest.col(k) = mesh.vertices[tet[k + 1]].cast<double>() - p0;
      StrainConstraint c;
      std::copy(tet.begin(), tet.end(), c.i);
      c.invRestShape = rest.inverse().cast<float>();
      c.stretchCompliance = material.elastic ? float(2.0 / (mu * restVolume[t])) : material.strainStretch.compliance;
      c.shearCompliance = material.elastic ? float(1.0 / (mu * restVolume[t])) : material.strainShear.compliance;
      model->strain.push_back(c);
    }
  }
  if (constraints.shapeMatching) model->shapeMatching = makeShapeMatchModel(*model, material.shapeMatching.compliance);
  colourDistances(*model, order);
  return model;
}

std::shared_ptr<const BodyModel> makeCloth(const TriMesh& mesh, const Material& material, SolveOrder order) {
  validateTriMesh(mesh);
  validateMaterial(material);
  if (material.elastic) throw Error("material: cloth takes compliances, not elastic moduli");
  auto model = std::make_shared<BodyModel>();
  model->restPositions = mesh.vertices;
  model->triangles = mesh.triangles;
  model->surface = mesh.triangles;
  std::vector<double> lumpedMass(mesh.vertices.size(), 0.0);
  for (const Triangle& t : mesh.triangles) {
    const auto& x = mesh.vertices;
    const double area = 0.5 * (x[t[1]] - x[t[0]]).cast<double>().cross((x[t[2]] - x[t[0]]).cast<double>()).norm();
    for (Index v : t) lumpedMass[v] += material.arealDensity * area / 3.0;
  }
  for (std::size_t v = 0; v < lumpedMass.size(); ++v)
    if (!(lumpedMass[v] > 0.0))
      throw Error(fmt::format("vertex {} is not used by any triangle; remove unused vertices first", v + 1));
  model->invMass = inverseMasses(lumpedMass, material.particleMass);
  model->damping = dampingOf(material);
  model->particleRadius = material.particleRadius;

  // Each edge with the vertices opposite it in its (one or two) triangles.
  std::map<Edge, std::vector<Index>> opposite;
  for (const Triangle& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) opposite[sortedEdge(t[k], t[(k + 1) % 3])].push_back(t[(k + 2) % 3]);
  for (const auto& [edge, across] : opposite) {
    if (across.size() > 2)
      throw Error(fmt::format("edge ({}, {}) is shared by {} triangles; cloth must be edge-manifold", edge.first,
                              edge.second, across.size()));
    addDistanceConstraint(*model, edge.first, edge.second, material.distance.compliance);
    if (across.size() == 2) {
      BendConstraint b{{edge.first, edge.second, across[0], across[1]}, 0.0f, material.bending.compliance};
      const auto& x = mesh.vertices;
      b.restAngle = evalBend(x[b.i[0]], x[b.i[1]], x[b.i[2]], x[b.i[3]], 0.0f).theta;
      model->bend.push_back(b);
    }
  }
  colourDistances(*model, order);
  if (order == SolveOrder::Coloured) {
    const Colouring levels = levelOrder(particlesOf(model->bend));
    model->bend = permuted(model->bend, levels.order);
    model->bendLevels = levels.colourStart;
  }
  return model;
}

namespace {
template <typename T>
std::size_t bytesOf(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}
}  // namespace

std::size_t BodyModel::bytes() const {
  std::size_t n = bytesOf(restPositions) + bytesOf(invMass) + bytesOf(tets) + bytesOf(triangles) + bytesOf(surface) +
                  bytesOf(distance) + bytesOf(volume) + bytesOf(strain) + bytesOf(bend) + bytesOf(distanceColours) +
                  bytesOf(tetColours) + bytesOf(distanceGroups) + bytesOf(tetGroups) + bytesOf(bendLevels);
  if (shapeMatching) n += bytesOf(shapeMatching->restOffsets) + bytesOf(shapeMatching->mass);
  return n;
}

void validateModel(const BodyModel& model) {
  const std::size_t n = model.particleCount();
  if (n == 0) throw Error("body model has no particles");
  if (model.invMass.size() != n)
    throw Error(fmt::format("body model has {} inverse masses for {} particles", model.invMass.size(), n));
  for (std::size_t i = 0; i < n; ++i) {
    if (!isFinite(model.restPositions[i])) throw Error(fmt::format("particle {} has a non-finite rest position", i));
    if (!finiteNonNegative(model.invMass[i]))
      throw Error(fmt::format("particle {} has inverse mass {}; masses must be positive (inverse mass 0 = kinematic)",
                              i, model.invMass[i]));
  }
  checkAll("distance constraint", model.distance, n);
  checkAll("volume constraint", model.volume, n);
  checkAll("bend constraint", model.bend, n);
  for (std::size_t c = 0; c < model.strain.size(); ++c) {
    const StrainConstraint& s = model.strain[c];
    checkItem("strain constraint", c, s.i, n, s.stretchCompliance);
    checkItem("strain constraint", c, s.i, n, s.shearCompliance);
    if (!s.invRestShape.allFinite()) throw Error(fmt::format("strain constraint {} has a non-finite rest shape", c));
  }
  for (std::size_t c = 0; c < model.distance.size(); ++c)
    if (!finiteNonNegative(model.distance[c].restLength))
      throw Error(fmt::format("distance constraint {} has rest length {}", c, model.distance[c].restLength));
  for (std::size_t c = 0; c < model.volume.size(); ++c)
    if (!std::isfinite(model.volume[c].restVolume))
      throw Error(fmt::format("volume constraint {} has a non-finite rest volume", c));
  for (std::size_t c = 0; c < model.bend.size(); ++c)
    if (!std::isfinite(model.bend[c].restAngle))
      throw Error(fmt::format("bend constraint {} has a non-finite rest angle", c));
  for (std::size_t t = 0; t < model.tets.size(); ++t)
    for (Index v : model.tets[t])
      if (v >= n) throw Error(fmt::format("tet {} refers to particle {}, but the body has {} particles", t, v, n));
  for (std::size_t t = 0; t < model.triangles.size(); ++t)
    for (Index v : model.triangles[t])
      if (v >= n) throw Error(fmt::format("triangle {} refers to particle {}, but the body has {} particles", t, v, n));
  for (std::size_t t = 0; t < model.surface.size(); ++t) {
    const Triangle& tri = model.surface[t];
    for (std::size_t k = 0; k < 3; ++k) {
      if (tri[k] >= n)
        throw Error(fmt::format("surface triangle {} ({}, {}, {}) refers to particle {}, but the body has {} particles",
                                t, tri[0], tri[1], tri[2], tri[k], n));
      for (std::size_t j = 0; j < k; ++j)
        if (tri[j] == tri[k]) throw Error(fmt::format("surface triangle {} uses particle {} twice", t, tri[k]));
    }
  }
  if (const auto& sm = model.shapeMatching) {
    if (sm->restOffsets.size() != n || sm->mass.size() != n)
      throw Error("shape matching rest frame does not match the body's particle count");
    if (!finiteNonNegative(sm->compliance)) throw Error("shape matching compliance must be finite and >= 0");
    if (!(sm->totalMass > 0.0f)) throw Error("shape matching needs a positive total mass");
  }
  checkColours("distance", model.distance, model.distanceColours, model.distanceGroups);
  checkColours("volume", model.volume, model.tetColours, model.tetGroups);
  checkColours("strain", model.strain, model.tetColours, model.tetGroups);
  checkColours("bend", model.bend, model.bendLevels, {});
  const ConstraintDamping& d = model.damping;
  for (float beta : {d.distance, d.volume, d.strainStretch, d.strainShear, d.bend, d.shapeMatching})
    if (!finiteNonNegative(beta)) throw Error(fmt::format("damping must be finite and >= 0, got {}", beta));
  if (!finiteNonNegative(model.particleRadius)) throw Error("particle radius must be finite and >= 0");
}

}  // namespace vrd
