// The world's contact between bodies and of a body with itself (body_contact.h): settings,
// detection with a spatial hash over the surfaces' swept boxes, the projection and readouts.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <span>

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
  surface.edgeFaces.assign(surface.edges.size(), {ContactSurface::kNoFace, ContactSurface::kNoFace});
  for (Index t = 0; t < model.surface.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const Triangle& tri = model.surface[t];
      const std::array<Index, 2> e{std::min(tri[k], tri[(k + 1) % 3]), std::max(tri[k], tri[(k + 1) % 3])};
      std::array<Index, 2>& faces = surface.edgeFaces[std::size_t(
          std::lower_bound(surface.edges.begin(), surface.edges.end(), e) - surface.edges.begin())];
      faces[faces[0] == ContactSurface::kNoFace ? 0 : 1] = t;
    }
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

// Each substep, from the positions at its start and the predictions, through spatial hashes of
// each body's surface triangles and edges by their swept boxes (start to prediction, grown by
// twice the body's thickness): a surface vertex whose swept box meets a triangle's, or an edge
// whose box meets an edge's, is a candidate against it, and becomes a contact where its contact plane
// (touchVertexTriangle, touchEdgeEdge, at the substep's start) is within twice the gap plus the
// pair's motion in the substep. The second gap is a skin: a vertex resting on a surface stays in
// the set instead of leaving it whenever it lifts by a rounding and coming back a substep later.
// A vertex or edge that would cross within the substep meets its plane first, however fast (no
// tunnelling from a state without penetration). A vertex more than the gap behind a plane is taken
// for the far side of a thin part and left alone. Self-contact leaves out the features that share
// a corner and those within the gap of each other in the rest shape (not all the features around
// a vertex: where a surface wrinkles under compression, its faces two apart are the ones that cross),
// and on a closed surface the edge pairs without a crease (markCreases).
void World::detectBodyContacts() {
  bodyContacts_.clear();
  // The bodies that touch something: themselves, or another active body with a surface.
  std::vector<BodyId> candidates, taking;
  for (BodyId id = 0; id < bodies_.size(); ++id)
    if (bodies_[id].state == BodyState::Active && !bodies_[id].model->surface.empty()) candidates.push_back(id);
  for (BodyId a : candidates)
    if (std::any_of(candidates.begin(), candidates.end(), [&](BodyId b) { return touching(a, b); }))
      taking.push_back(a);
  if (taking.empty()) return;

  broadPhases_.resize(bodies_.size());
  std::size_t mostTriangles = 0, mostEdges = 0;
  for (BodyId id : taking) {
    const Body& b = bodies_[id];
    ContactBroadPhase& broad = broadPhases_[id];
    broad.offset = offsetBetween(b, bodies_[taking.front()]);
    broad.boxes.clear();
    broad.bounds.setEmpty();
    const float grow = 2.0f * bodyContactSettings_[id].thickness;
    double extent = 0.0;
    for (const Triangle& t : b.model->surface) {
      Box3f box = sweptBox(b.firstParticle + t[0], broad.offset, grow);
      box.extend(sweptBox(b.firstParticle + t[1], broad.offset, grow));
      box.extend(sweptBox(b.firstParticle + t[2], broad.offset, grow));
      broad.boxes.push_back(box);
      broad.bounds.extend(box);
      if (const float size = box.sizes().maxCoeff(); std::isfinite(size)) extent += size;
    }
    broad.edgeBoxes.clear();
    for (const std::array<Index, 2>& e : contactSurfaces_[id].edges)
      broad.edgeBoxes.push_back(sweptBox(b.firstParticle + e[0], broad.offset, grow)
                                    .extend(sweptBox(b.firstParticle + e[1], broad.offset, grow)));
    markCreases(id);
    // Cells the size of a typical triangle's box: a vertex's box meets a few cells, a triangle's a few.
    broad.hash.build(broad.boxes, std::max(float(extent / double(broad.boxes.size())), 1e-6f));
    broad.edgeHash.build(broad.edgeBoxes, std::max(float(extent / double(broad.boxes.size())), 1e-6f));
    mostTriangles = std::max(mostTriangles, b.model->surface.size());
    mostEdges = std::max(mostEdges, contactSurfaces_[id].edges.size());
  }
  seen_.assign(std::max(mostTriangles, mostEdges), 0);
  contactQuery_ = 0;
  for (BodyId a : taking)
    for (BodyId b : taking) {
      if (!touching(a, b) || !broadPhases_[a].bounds.intersects(broadPhases_[b].bounds)) continue;
      detectVertexTriangle(a, b);
      if (b >= a) detectEdgeEdge(a, b);
    }
  // The order the warm start matches contacts in.
  std::sort(bodyContacts_.begin(), bodyContacts_.end(),
            [](const BodyContact& x, const BodyContact& y) { return x.key < y.key; });
}

// Self-contact of a closed surface needs edge pairs only where an edge is a crease: between two
// smooth stretches of surface a vertex meets the other side's faces before any edge can cross
// between vertices. Creases from the substep's start (a fold makes new ones), by the angle between
// the edge's two faces; a boundary edge (a surface that is not closed) counts as one.
void World::markCreases(BodyId id) {
  ContactBroadPhase& broad = broadPhases_[id];
  const Body& b = bodies_[id];
  broad.sharp.clear();
  if (!bodyContactSettings_[id].self || b.model->tets.empty()) return;  // every edge of a cloth or between bodies
  const ContactSurface& surface = contactSurfaces_[id];
  broad.normals.clear();  // each face's once, for its three edges
  for (const Triangle& tri : b.model->surface) {
    const Vec3 &x0 = local_[b.firstParticle + tri[0]].pos, &x1 = local_[b.firstParticle + tri[1]].pos,
               &x2 = local_[b.firstParticle + tri[2]].pos;
    broad.normals.push_back((x1 - x0).cross(x2 - x0).normalized());
  }
  constexpr float kCreaseCos = 0.866f;  // faces more than 30 degrees apart
  broad.sharp.resize(surface.edges.size());
  for (std::size_t e = 0; e < surface.edges.size(); ++e) {
    const std::array<Index, 2>& f = surface.edgeFaces[e];
    broad.sharp[e] = f[1] == ContactSurface::kNoFace || !(broad.normals[f[0]].dot(broad.normals[f[1]]) > kCreaseCos);
  }
}

namespace {

// Whether two features of one body share a corner: self-contact leaves them out.
bool shareCorner(std::span<const Index> f, std::span<const Index> g) {
  return std::any_of(f.begin(), f.end(), [&](Index c) { return std::find(g.begin(), g.end(), c) != g.end(); });
}

}  // namespace

void World::detectVertexTriangle(BodyId a, BodyId bId) {
  const Point* const pred = predicted_.data();
  const Point* const start = local_.data();
  const Body &body = bodies_[a], &other = bodies_[bId];
  const float thicknessA = bodyContactSettings_[a].thickness;
  const ContactSurface& surfaceB = contactSurfaces_[bId];
  const ContactBroadPhase& broad = broadPhases_[bId];
  const Vec3 offsetA = broadPhases_[a].offset, offset = offsetBetween(other, body);
  const std::vector<Vec3>& rest = body.model->restPositions;
  const ContactPair pair = contactPair(bodyContactSettings_[a], bodyContactSettings_[bId]);
  const float gap = pair.gap;
  for (Index v : contactSurfaces_[a].vertices) {
    const Index i = body.firstParticle + v;
    const Box3f box = sweptBox(i, offsetA, 2.0f * thicknessA);
    if (!box.intersects(broad.bounds)) continue;
    const float motion = (pred[i].pos - start[i].pos).norm();
    const std::uint32_t query = ++contactQuery_;
    broad.hash.query(box, [&](Index t) {
      if (seen_[t] == query) return;
      seen_[t] = query;
      if (!box.intersects(broad.boxes[t])) return;
      const Triangle& tri = other.model->surface[t];
      if (a == bId && shareCorner(std::span(&v, 1), std::span(tri))) return;
      const std::array<Index, 4> p{i, other.firstParticle + tri[0], other.firstParticle + tri[1],
                                   other.firstParticle + tri[2]};
      if (pred[p[0]].w == 0.0f && pred[p[1]].w == 0.0f && pred[p[2]].w == 0.0f && pred[p[3]].w == 0.0f) return;
      const std::optional<VertexTriangleTouch> touch = touchVertexTriangle(
          start[i].pos, start[p[1]].pos + offset, start[p[2]].pos + offset, start[p[3]].pos + offset,
          !other.model->tets.empty());  // a soft body's surface is closed
      if (!touch) return;
      float reach = 0.0f;
      for (int k = 1; k < 4; ++k) reach = std::max(reach, (pred[p[k]].pos - start[p[k]].pos).norm());
      if (!(touch->distance >= -gap && touch->distance <= 2.0f * gap + motion + reach)) return;
      if (a == bId) {  // within the gap at rest: as the body should be
        const std::array<float, 3> w = closestPointOnTriangle(rest[v], rest[tri[0]], rest[tri[1]], rest[tri[2]]);
        if ((rest[v] - (w[0] * rest[tri[0]] + w[1] * rest[tri[1]] + w[2] * rest[tri[2]])).norm() <= gap) return;
      }
      const std::uint64_t key = std::uint64_t(i) << 32 | (surfaceB.firstTriangleKey + t);
      bodyContacts_.push_back(
          {p, {1.0f, -touch->b[0], -touch->b[1], -touch->b[2]}, 1, key, offset, touch->normal, pair});
    });
  }
}

// Each edge pair once: from the body with the lower id (b >= a), within a body from the lower edge.
void World::detectEdgeEdge(BodyId a, BodyId bId) {
  const Point* const pred = predicted_.data();
  const Point* const start = local_.data();
  const Body &body = bodies_[a], &other = bodies_[bId];
  const ContactSurface &surfaceA = contactSurfaces_[a], &surfaceB = contactSurfaces_[bId];
  const ContactBroadPhase& broad = broadPhases_[bId];
  const Vec3 offset = offsetBetween(other, body);
  const std::vector<Vec3>& rest = body.model->restPositions;
  const ContactPair pair = contactPair(bodyContactSettings_[a], bodyContactSettings_[bId]);
  const float gap = pair.gap;
  // Within a body in self-contact, only creases query (broad.sharp); a pair of two creases once.
  const std::vector<char>& sharp = broad.sharp;
  for (Index queried = 0; queried < surfaceA.edges.size(); ++queried) {
    if (!sharp.empty() && !sharp[queried]) continue;
    const Box3f& box = broadPhases_[a].edgeBoxes[queried];
    if (!box.intersects(broad.bounds)) continue;
    const std::uint32_t query = ++contactQuery_;
    broad.edgeHash.query(box, [&](Index met) {
      if (seen_[met] == query) return;
      seen_[met] = query;
      if (a == bId && (met == queried || (met < queried && (sharp.empty() || sharp[met])))) return;
      if (!box.intersects(broad.edgeBoxes[met])) return;
      // Within a body, each pair from its lower edge, whichever found it: the same contact (key,
      // corner order) from every substep, for the warm start.
      const Index e = a == bId ? std::min(queried, met) : queried, f = a == bId ? std::max(queried, met) : met;
      const std::array<Index, 2>& edge = surfaceA.edges[e];
      const Index i0 = body.firstParticle + edge[0], i1 = body.firstParticle + edge[1];
      const float motion = std::max((pred[i0].pos - start[i0].pos).norm(), (pred[i1].pos - start[i1].pos).norm());
      const std::array<Index, 2>& g = surfaceB.edges[f];
      if (a == bId && shareCorner(std::span(edge), std::span(g))) return;
      const std::array<Index, 4> p{i0, i1, other.firstParticle + g[0], other.firstParticle + g[1]};
      if (pred[p[0]].w == 0.0f && pred[p[1]].w == 0.0f && pred[p[2]].w == 0.0f && pred[p[3]].w == 0.0f) return;
      const std::optional<EdgeEdgeTouch> touch =
          touchEdgeEdge(start[p[0]].pos, start[p[1]].pos, start[p[2]].pos + offset, start[p[3]].pos + offset);
      if (!touch) return;
      const float reach =
          std::max((pred[p[2]].pos - start[p[2]].pos).norm(), (pred[p[3]].pos - start[p[3]].pos).norm());
      if (!(touch->distance <= gap + motion + reach)) return;
      if (a == bId) {  // within the gap at rest: as the body should be
        const auto t = touchEdgeEdge(rest[edge[0]], rest[edge[1]], rest[g[0]], rest[g[1]]);
        if (t && t->distance <= gap) return;
      }
      const std::uint64_t key =
          1ull << 63 | std::uint64_t(surfaceA.firstEdgeKey + e) << 32 | (surfaceB.firstEdgeKey + f);
      bodyContacts_.push_back(
          {p, {1.0f - touch->s, touch->s, touch->t - 1.0f, -touch->t}, 2, key, offset, touch->normal, pair});
    });
  }
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
