// The world's contact between bodies and of a body with itself (body_contact.h): settings,
// detection through each surface's tree of swept boxes (surface_tree.h), the projection and readouts.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <span>

#include "solver_team.h"
#include "vrdeform/error.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

void checkNonNegative(float value, const char* what) {
  if (!(std::isfinite(value) && value >= 0.0f))
    throw Error(fmt::format("setBodyContact: {} must be finite and >= 0 (got {})", what, value));
}

Vec3 offsetBetween(const Body& from, const Body& to) { return (from.origin - to.origin).cast<float>(); }

}  // namespace

void World::setBodyContact(BodyId id, const BodyContactSettings& settings) {
  if (id >= bodies_.size()) throw Error(fmt::format("setBodyContact: no body {}", id));
  checkNonNegative(settings.thickness, "thickness");
  checkNonNegative(settings.staticFriction, "static friction");
  checkNonNegative(settings.dynamicFriction, "dynamic friction");
  checkNonNegative(settings.compliance, "compliance");
  bodyContactSettings_[id] = settings;
}

void World::setPairContact(BodyId a, BodyId b, bool enabled) {
  if (a >= bodies_.size() || b >= bodies_.size() || a == b)
    throw Error(fmt::format("setPairContact: bodies {} and {} are not two bodies of this world", a, b));
  const std::pair pair{std::min(a, b), std::max(a, b)};
  const auto at = std::lower_bound(pairsOff_.begin(), pairsOff_.end(), pair);
  const bool off = at != pairsOff_.end() && *at == pair;
  if (enabled && off) pairsOff_.erase(at);
  if (!enabled && !off) pairsOff_.insert(at, pair);
}

bool World::pairContact(BodyId a, BodyId b) const {
  return !std::binary_search(pairsOff_.begin(), pairsOff_.end(), std::pair{std::min(a, b), std::max(a, b)});
}

World::ContactSurface World::contactSurfaceOf(const BodyModel& model) {
  ContactSurface surface;
  for (const Triangle& t : model.surface) {
    surface.vertices.insert(surface.vertices.end(), t.begin(), t.end());
    for (int k = 0; k < 3; ++k)
      surface.edges.push_back({std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])});
  }
  const auto sortUnique = [](auto& v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
  };
  sortUnique(surface.vertices);
  sortUnique(surface.edges);
  const auto position = [](const auto& sorted, const auto& value) {
    return Index(std::lower_bound(sorted.begin(), sorted.end(), value) - sorted.begin());
  };
  surface.edgeFaces.assign(surface.edges.size(), {ContactSurface::kNoFace, ContactSurface::kNoFace});
  std::vector<Index> vertexOwner(surface.vertices.size(), ContactSurface::kNoFace);
  for (Index t = 0; t < model.surface.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const Triangle& tri = model.surface[t];
      std::array<Index, 2>& faces = surface.edgeFaces[position(
          surface.edges, std::array<Index, 2>{std::min(tri[k], tri[(k + 1) % 3]), std::max(tri[k], tri[(k + 1) % 3])})];
      faces[faces[0] == ContactSurface::kNoFace ? 0 : 1] = t;
      Index& owner = vertexOwner[position(surface.vertices, tri[k])];
      if (owner == ContactSurface::kNoFace) owner = t;
    }
  // Each vertex and edge under its first triangle (counting sort by owner).
  const auto own = [&](const auto& ownerOf, std::size_t count, std::vector<Index>& start, std::vector<Index>& owned) {
    start.assign(model.surface.size() + 1, 0);
    for (std::size_t k = 0; k < count; ++k) ++start[ownerOf(k) + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    owned.resize(count);
    std::vector<Index> fill(start.begin(), start.end() - 1);
    for (std::size_t k = 0; k < count; ++k) owned[fill[ownerOf(k)]++] = Index(k);
  };
  own([&](std::size_t k) { return vertexOwner[k]; }, surface.vertices.size(), surface.vertexStart,
      surface.ownedVertices);
  own([&](std::size_t k) { return surface.edgeFaces[k][0]; }, surface.edges.size(), surface.edgeStart,
      surface.ownedEdges);
  for (const Triangle& t : model.surface)
    surface.triangleCorners.push_back(
        {position(surface.vertices, t[0]), position(surface.vertices, t[1]), position(surface.vertices, t[2])});
  for (const std::array<Index, 2>& e : surface.edges)
    surface.edgeCorners.push_back({position(surface.vertices, e[0]), position(surface.vertices, e[1])});
  surface.tree.build(model.surface, model.restPositions);
  return surface;
}

bool World::touching(BodyId a, BodyId b) const {
  const BodyContactSettings &sa = bodyContactSettings_[a], &sb = bodyContactSettings_[b];
  return a == b ? sa.self : sa.bodies && sb.bodies && pairContact(a, b);
}

Box3f World::sweptBox(Index i, const Vec3& offset, float grow) const {
  Box3f box(local_[i].pos + offset);
  box.extend(predicted_[i].pos + offset);
  return Box3f(box.min().array() - grow, box.max().array() + grow);
}

namespace {

Vec3 faceNormal(const Vec3& x0, const Vec3& x1, const Vec3& x2) { return (x1 - x0).cross(x2 - x0).normalized(); }

}  // namespace

struct World::ContactSides {
  BodyId a, b;
  const Body &bodyA, &bodyB;
  const ContactSurface &surfaceA, &surfaceB;
  const ContactBroadPhase &broadA, &broadB;
  Vec3 offsetBA, offsetAB;  // b's frame to a's, and back
  ContactPair pair;
  std::vector<BodyContact>& found;  // where the contacts go
  ContactSides swapped() const {
    return {b, a, bodyB, bodyA, surfaceB, surfaceA, broadB, broadA, offsetAB, offsetBA, pair, found};
  }
};

World::ContactSides World::contactSides(BodyId a, BodyId b, std::vector<BodyContact>& found) const {
  return {a,
          b,
          bodies_[a],
          bodies_[b],
          contactSurfaces_[a],
          contactSurfaces_[b],
          broadPhases_[a],
          broadPhases_[b],
          offsetBetween(bodies_[b], bodies_[a]),
          offsetBetween(bodies_[a], bodies_[b]),
          contactPair(bodyContactSettings_[a], bodyContactSettings_[b]),
          found};
}

// Each substep, from the positions at its start and the predictions: each body's surface tree is
// refitted to its triangles' swept boxes (start to prediction, grown by twice the body's
// thickness), and the pairs of triangles whose boxes overlap (of two bodies, or of one body's
// patches that face apart: surface_tree.h) bring their vertices and edges together
// (detectTrianglePair). A vertex whose swept box meets a triangle's, or an edge whose box meets an
// edge's, becomes a contact where its contact plane (touchVertexTriangle, touchEdgeEdge, at the
// substep's start) is within twice the gap plus the pair's motion in the substep. The second gap
// is a skin: a vertex resting on a surface stays in the set instead of leaving it whenever it
// lifts by a rounding and coming back a substep later. A vertex or edge that would cross within
// the substep meets its plane first, however fast (no tunnelling from a state without
// penetration). A vertex more than the gap behind a plane is taken for the far side of a thin part
// and left alone. Self-contact leaves out the features that share a corner and those within the
// gap of each other in the rest shape (not all the features around a vertex: where a surface
// wrinkles under compression, its faces two apart are the ones that cross), and on a closed
// surface the edge pairs without a crease (markCreases).
// A team shares the work: each member makes its share of every surface's vertex boxes and
// normals, then its share of the trees' parts (their triangles' boxes, the refit) and of the
// edges, then takes pairs of parts to traverse as it comes free; the leader joins the contacts.
// Contacts are sorted by their keys, so the team finds the one-thread list.
void World::detectBodyContacts(const SolverTeam& team) {
  if (contactBodies_.empty()) return;
  for (BodyId id : contactBodies_) {
    const Body& b = bodies_[id];
    const Index first = b.firstParticle;
    const ContactSurface& surface = contactSurfaces_[id];
    ContactBroadPhase& broad = broadPhases_[id];
    const float grow = 2.0f * bodyContactSettings_[id].thickness;
    const auto [v0, v1] = team.share(0, surface.vertices.size(), 64);
    for (std::size_t k = v0; k < v1; ++k)
      broad.vertexBoxes[k] = sweptBox(first + surface.vertices[k], broad.offset, grow);
    const auto [t0, t1] = team.share(0, surface.triangleCorners.size(), 64);
    for (std::size_t k = t0; k < t1; ++k) {
      const Triangle& t = b.model->surface[k];
      broad.moving[k] = std::any_of(t.begin(), t.end(), [&](Index v) { return predicted_[first + v].w > 0.0f; });
      if (broad.startNormals.empty()) continue;  // the normals serve self-contact only
      broad.startNormals[k] = faceNormal(local_[first + t[0]].pos, local_[first + t[1]].pos, local_[first + t[2]].pos);
      broad.endNormals[k] =
          faceNormal(predicted_[first + t[0]].pos, predicted_[first + t[1]].pos, predicted_[first + t[2]].pos);
    }
  }
  team.barrier();
  // The trees' parts (their triangles' boxes from their corners', then the refit), and the edges'
  // boxes and creases.
  const auto [p0, p1] = team.share(0, contactParts_.size(), 1);
  for (std::size_t k = p0; k < p1; ++k) {
    const auto [id, part] = contactParts_[k];
    ContactSurface& surface = contactSurfaces_[id];
    ContactBroadPhase& broad = broadPhases_[id];
    const std::vector<Box3f>& at = broad.vertexBoxes;
    for (Index t : surface.tree.partTriangles(part)) {
      const std::array<Index, 3>& c = surface.triangleCorners[t];
      broad.boxes[t] = at[c[0]].merged(at[c[1]]).merged(at[c[2]]);
    }
    surface.tree.refitPart(part, {broad.boxes, broad.startNormals, broad.endNormals, broad.moving});
  }
  for (BodyId id : contactBodies_) {
    const ContactSurface& surface = contactSurfaces_[id];
    ContactBroadPhase& broad = broadPhases_[id];
    const auto [e0, e1] = team.share(0, surface.edges.size(), 64);
    for (std::size_t e = e0; e < e1; ++e) {
      const std::array<Index, 2>& c = surface.edgeCorners[e];
      broad.edgeBoxes[e] = broad.vertexBoxes[c[0]].merged(broad.vertexBoxes[c[1]]);
    }
    markCreases(id, e0, e1);
  }
  std::vector<BodyContact>& found = team.leader() ? bodyContacts_ : memberContacts_[std::size_t(team.index)].body;
  found.clear();
  team.shareOut(contactTasks_.size(), [&](std::size_t k) {
    const ContactTask& task = contactTasks_[k];
    const ContactSides ab = contactSides(task.a, task.b, found), ba = ab.swapped();
    const auto meet = [&](Index t, Index u) { detectTrianglePair(ab, ba, t, u); };
    const SurfaceTree& tree = contactSurfaces_[task.a].tree;
    if (task.a == task.b)
      tree.selfPairs(!bodies_[task.a].model->tets.empty(), task.i, task.j, meet);  // a soft body's surface is closed
    else
      tree.pairsWith(contactSurfaces_[task.b].tree, task.i, task.j, meet);
  });
  team.barrier();
  if (!team.leader()) return;
  for (int k = 1; k < team.size; ++k) {
    const std::vector<BodyContact>& other = memberContacts_[std::size_t(k)].body;
    bodyContacts_.insert(bodyContacts_.end(), other.begin(), other.end());
  }
  // The order the warm start matches contacts in (and the one-thread order).
  std::sort(bodyContacts_.begin(), bodyContacts_.end(),
            [](const BodyContact& x, const BodyContact& y) { return x.key < y.key; });
}

// By the leader before detection: the bodies that touch something (themselves, or another active
// body with a surface), their broad phases sized and framed, and the work: the parts of their
// trees, and the pairs of parts of the pairs of bodies that touch.
void World::prepareBodyContacts() {
  bodyContacts_.clear();
  contactBodies_.clear();
  contactParts_.clear();
  contactTasks_.clear();
  std::vector<BodyId> candidates;
  for (BodyId id = 0; id < bodies_.size(); ++id)
    if (bodies_[id].state == BodyState::Active && !bodies_[id].model->surface.empty()) candidates.push_back(id);
  for (BodyId a : candidates)
    if (std::any_of(candidates.begin(), candidates.end(), [&](BodyId b) { return touching(a, b); }))
      contactBodies_.push_back(a);
  broadPhases_.resize(bodies_.size());
  for (BodyId id : contactBodies_) {
    const ContactSurface& surface = contactSurfaces_[id];
    ContactBroadPhase& broad = broadPhases_[id];
    broad.offset = offsetBetween(bodies_[id], bodies_[contactBodies_.front()]);
    const bool self = bodyContactSettings_[id].self;
    broad.vertexBoxes.resize(surface.vertices.size());
    broad.boxes.resize(surface.triangleCorners.size());
    broad.edgeBoxes.resize(surface.edges.size());
    broad.moving.resize(surface.triangleCorners.size());
    broad.startNormals.resize(self ? surface.triangleCorners.size() : 0);
    broad.endNormals.resize(broad.startNormals.size());
    broad.sharp.resize(self && !bodies_[id].model->tets.empty() ? surface.edges.size() : 0);
    for (std::uint32_t p = 0; p < surface.tree.parts(); ++p) contactParts_.push_back({id, p});
  }
  for (std::size_t x = 0; x < contactBodies_.size(); ++x)
    for (std::size_t y = x; y < contactBodies_.size(); ++y) {
      const BodyId a = contactBodies_[x], b = contactBodies_[y];
      if (!touching(a, b)) continue;
      const auto parts = [&](BodyId id) { return std::uint32_t(contactSurfaces_[id].tree.parts()); };
      for (std::uint32_t i = 0; i < parts(a); ++i)
        for (std::uint32_t j = a == b ? i : 0; j < parts(b); ++j) contactTasks_.push_back({a, b, i, j});
    }
}

// Self-contact of a closed surface needs edge pairs only where an edge is a crease: between two
// smooth stretches of surface a vertex meets the other side's faces before any edge can cross
// between vertices. Creases from the substep's start (a fold makes new ones), by the angle between
// the edge's two faces; a boundary edge (a surface that is not closed) counts as one.
// No creases (sharp empty): every edge of a cloth or between bodies.
void World::markCreases(BodyId id, std::size_t begin, std::size_t end) {
  ContactBroadPhase& broad = broadPhases_[id];
  if (broad.sharp.empty()) return;
  const ContactSurface& surface = contactSurfaces_[id];
  constexpr float kCreaseCos = 0.866f;  // faces more than 30 degrees apart
  for (std::size_t e = begin; e < end; ++e) {
    const std::array<Index, 2>& f = surface.edgeFaces[e];
    broad.sharp[e] =
        f[1] == ContactSurface::kNoFace || !(broad.startNormals[f[0]].dot(broad.startNormals[f[1]]) > kCreaseCos);
  }
}

// Triangle t of a and u of b (boxes overlapping; ba: the sides swapped): each one's vertices
// against the other, and their edges against each other's, where their boxes overlap (and, within
// a closed surface in self-contact, one of the two edges is a crease: markCreases).
void World::detectTrianglePair(const ContactSides& ab, const ContactSides& ba, Index t, Index u) const {
  const ContactSurface &sa = ab.surfaceA, &sb = ab.surfaceB;
  const ContactBroadPhase &broadA = ab.broadA, &broadB = ab.broadB;
  for (Index k = sa.vertexStart[t]; k < sa.vertexStart[t + 1]; ++k)
    if (const Index v = sa.ownedVertices[k]; overlap(broadA.vertexBoxes[v], broadB.boxes[u]))
      detectVertexTriangle(ab, v, u);
  for (Index k = sb.vertexStart[u]; k < sb.vertexStart[u + 1]; ++k)
    if (const Index v = sb.ownedVertices[k]; overlap(broadB.vertexBoxes[v], broadA.boxes[t]))
      detectVertexTriangle(ba, v, t);
  const bool creasesOnly = ab.a == ab.b && !broadA.sharp.empty();
  for (Index k = sa.edgeStart[t]; k < sa.edgeStart[t + 1]; ++k) {
    const Index e = sa.ownedEdges[k];
    const bool smooth = creasesOnly && !broadA.sharp[e];
    for (Index l = sb.edgeStart[u]; l < sb.edgeStart[u + 1]; ++l)
      if (const Index f = sb.ownedEdges[l];
          !(smooth && !broadB.sharp[f]) && overlap(broadA.edgeBoxes[e], broadB.edgeBoxes[f]))
        detectEdgeEdge(ab, e, f);
  }
}

namespace {

// Whether two features of one body share a corner: self-contact leaves them out.
bool shareCorner(std::span<const Index> f, std::span<const Index> g) {
  return std::any_of(f.begin(), f.end(), [&](Index c) { return std::find(g.begin(), g.end(), c) != g.end(); });
}

}  // namespace

// Surface vertex `vertex` of a (its position in the surface's vertex list) against triangle t of b,
// their boxes overlapping.
void World::detectVertexTriangle(const ContactSides& ab, Index vertex, Index t) const {
  const Point* const pred = predicted_.data();
  const Point* const start = local_.data();
  const Index v = ab.surfaceA.vertices[vertex], i = ab.bodyA.firstParticle + v;
  const Triangle& tri = ab.bodyB.model->surface[t];
  const bool self = ab.a == ab.b;
  if (self && shareCorner(std::span(&v, 1), std::span(tri))) return;
  const Index first = ab.bodyB.firstParticle;
  const std::array<Index, 4> p{i, first + tri[0], first + tri[1], first + tri[2]};
  if (pred[p[0]].w == 0.0f && pred[p[1]].w == 0.0f && pred[p[2]].w == 0.0f && pred[p[3]].w == 0.0f) return;
  const Vec3& offset = ab.offsetBA;
  const std::optional<VertexTriangleTouch> touch =
      touchVertexTriangle(start[i].pos, start[p[1]].pos + offset, start[p[2]].pos + offset, start[p[3]].pos + offset,
                          !ab.bodyB.model->tets.empty());  // a soft body's surface is closed
  if (!touch) return;
  float reach = 0.0f;
  for (int k = 1; k < 4; ++k) reach = std::max(reach, (pred[p[k]].pos - start[p[k]].pos).norm());
  const float gap = ab.pair.gap, motion = (pred[i].pos - start[i].pos).norm();
  if (!(touch->distance >= -gap && touch->distance <= 2.0f * gap + motion + reach)) return;
  if (self) {  // within the gap at rest: as the body should be
    const std::vector<Vec3>& rest = ab.bodyA.model->restPositions;
    const std::array<float, 3> w = closestPointOnTriangle(rest[v], rest[tri[0]], rest[tri[1]], rest[tri[2]]);
    if ((rest[v] - (w[0] * rest[tri[0]] + w[1] * rest[tri[1]] + w[2] * rest[tri[2]])).norm() <= gap) return;
  }
  const std::uint64_t key = std::uint64_t(i) << 32 | (ab.surfaceB.firstTriangleKey + t);
  ab.found.push_back({p, {1.0f, -touch->b[0], -touch->b[1], -touch->b[2]}, 1, key, offset, touch->normal, ab.pair});
}

// Surface edges e of a and f of b (positions in the surfaces' edge lists), their boxes
// overlapping. Within a body, each pair from its lower edge: the same contact (key, corner order)
// from every substep, for the warm start.
void World::detectEdgeEdge(const ContactSides& ab, Index e, Index f) const {
  const bool self = ab.a == ab.b;
  if (self && f < e) std::swap(e, f);
  const Point* const pred = predicted_.data();
  const Point* const start = local_.data();
  const std::array<Index, 2>&edge = ab.surfaceA.edges[e], &g = ab.surfaceB.edges[f];
  if (self && shareCorner(std::span(edge), std::span(g))) return;
  const Index i0 = ab.bodyA.firstParticle + edge[0], i1 = ab.bodyA.firstParticle + edge[1];
  const std::array<Index, 4> p{i0, i1, ab.bodyB.firstParticle + g[0], ab.bodyB.firstParticle + g[1]};
  if (pred[p[0]].w == 0.0f && pred[p[1]].w == 0.0f && pred[p[2]].w == 0.0f && pred[p[3]].w == 0.0f) return;
  const Vec3& offset = ab.offsetBA;
  const std::optional<EdgeEdgeTouch> touch =
      touchEdgeEdge(start[p[0]].pos, start[p[1]].pos, start[p[2]].pos + offset, start[p[3]].pos + offset);
  if (!touch) return;
  const float motion = std::max((pred[i0].pos - start[i0].pos).norm(), (pred[i1].pos - start[i1].pos).norm());
  const float reach = std::max((pred[p[2]].pos - start[p[2]].pos).norm(), (pred[p[3]].pos - start[p[3]].pos).norm());
  if (!(touch->distance <= ab.pair.gap + motion + reach)) return;
  if (self) {  // within the gap at rest: as the body should be
    const std::vector<Vec3>& rest = ab.bodyA.model->restPositions;
    const auto t = touchEdgeEdge(rest[edge[0]], rest[edge[1]], rest[g[0]], rest[g[1]]);
    if (t && t->distance <= ab.pair.gap) return;
  }
  const std::uint64_t key =
      1ull << 63 | std::uint64_t(ab.surfaceA.firstEdgeKey + e) << 32 | (ab.surfaceB.firstEdgeKey + f);
  ab.found.push_back(
      {p, {1.0f - touch->s, touch->s, touch->t - 1.0f, -touch->t}, 2, key, offset, touch->normal, ab.pair});
}

// By the leader, after the other contacts: each contact's plane, then its friction.
void World::solveBodyContacts(float invH) {
  Point* const pred = predicted_.data();
  const Point* const start = local_.data();
  for (std::size_t c = 0; c < bodyContacts_.size(); ++c) {
    const BodyContact& con = bodyContacts_[c];
    std::array<Point, 4> x;
    std::array<Vec3, 4> x0;
    for (std::size_t k = 0; k < 4; ++k) {
      const Vec3 offset = k < con.firstCorners ? Vec3::Zero() : con.offset;
      x[k] = {pred[con.particle[k]].pos + offset, pred[con.particle[k]].w};
      x0[k] = start[con.particle[k]].pos + offset;
    }
    const BodyContactCorrection r =
        solveBodyContact(x, con, bodyContactLambda_[c], XpbdCoefficients::make(con.pair.compliance, 0.0f, invH));
    bodyContactLambda_[c] += r.dLambda;
    for (std::size_t k = 0; k < 4; ++k) x[k].pos += r.dx[k];
    const Vec3 friction = bodyContactFriction(x, x0, con, bodyContactLambda_[c], bodyContactFrictionLambda_[c]);
    bodyContactFrictionLambda_[c] += friction;
    for (std::size_t k = 0; k < 4; ++k) pred[con.particle[k]].pos += r.dx[k] + (x[k].w * con.weight[k]) * friction;
  }
}

float World::deepestPenetration() const {
  float deepest = 0.0f;
  for (const BodyContact& con : bodyContacts_) {
    Vec3 d = Vec3::Zero();
    for (std::size_t k = 0; k < 4; ++k)
      d += con.weight[k] * (local_[con.particle[k]].pos + (k < con.firstCorners ? Vec3::Zero() : con.offset));
    deepest = std::max(deepest, -con.normal.dot(d));
  }
  return deepest;
}

Vec3 World::bodyContactForce(BodyId on, BodyId by) const {
  if (on >= bodies_.size() || by >= bodies_.size())
    throw Error(fmt::format("bodyContactForce: no body {}", std::max(on, by)));
  const float h = substepSize();
  Vec3 sum = Vec3::Zero();
  for (std::size_t c = 0; c < bodyContacts_.size(); ++c) {
    const BodyContact& con = bodyContacts_[c];
    const BodyId first = particleBody_[con.particle[0]], second = particleBody_[con.particle[3]];
    const Vec3 push = bodyContactLambda_[c] * con.normal + bodyContactFrictionLambda_[c];
    if (first == on && second == by) sum += push;
    if (second == on && first == by) sum -= push;
  }
  return sum / (h * h);
}

}  // namespace vrd
