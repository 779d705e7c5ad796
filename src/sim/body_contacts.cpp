// The world's contact between bodies and of a body with itself (body_contact.h): settings,
// detection with a spatial hash over the surfaces' swept boxes, the projection and readouts.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "vrdeform/error.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

void checkNonNegative(float value, const char* what) {
  if (!(std::isfinite(value) && value >= 0.0f))
    throw Error(fmt::format("setBodyContact: {} must be finite and >= 0 (got {})", what, value));
}

// For each particle, the particles that share an element (a tet, or a cloth's triangle) with it.
template <typename Element>
void neighboursOf(const std::vector<Element>& elements, std::size_t particles, std::vector<Index>& start,
                  std::vector<Index>& out) {
  std::vector<std::vector<Index>> lists(particles);
  for (const Element& e : elements)
    for (Index a : e)
      for (Index b : e)
        if (a != b) lists[a].push_back(b);
  start.assign(particles + 1, 0);
  out.clear();
  for (std::size_t v = 0; v < particles; ++v) {
    std::sort(lists[v].begin(), lists[v].end());
    lists[v].erase(std::unique(lists[v].begin(), lists[v].end()), lists[v].end());
    out.insert(out.end(), lists[v].begin(), lists[v].end());
    start[v + 1] = Index(out.size());
  }
}

Vec3 offsetBetween(const Body& from, const Body& to) { return (from.origin - to.origin).cast<float>(); }

}  // namespace

void World::setBodyContact(BodyId id, const BodyContactSettings& settings) {
  if (id >= bodies_.size()) throw Error(fmt::format("setBodyContact: no body {}", id));
  checkNonNegative(settings.thickness, "thickness");
  checkNonNegative(settings.staticFriction, "static friction");
  checkNonNegative(settings.dynamicFriction, "dynamic friction");
  checkNonNegative(settings.compliance, "compliance");
  ContactSurface& s = contactSurfaces_[id];
  const BodyModel& m = *bodies_[id].model;
  if (settings.self && s.neighbourStart.empty()) {
    if (m.tets.empty())
      neighboursOf(m.triangles, m.particleCount(), s.neighbourStart, s.neighbours);
    else
      neighboursOf(m.tets, m.particleCount(), s.neighbourStart, s.neighbours);
  }
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

// Each substep, from the positions at its start and the predictions: every surface vertex whose
// swept box (grown by its body's thickness) meets a surface triangle's swept box (grown by the
// other's) is a candidate, and becomes a contact where its contact plane (touchVertexTriangle, at
// the substep's start) is within the gap plus the pair's motion in the substep: so a vertex that
// would cross a triangle within the substep meets its plane first, however fast (no tunnelling
// from a state without penetration). A vertex more than the gap behind a plane is taken for the
// far side of a thin part and left alone. Self-contact leaves out the triangles that hold the
// vertex or a particle sharing a tet (a cloth: a triangle) with it, and those within the gap of it
// in the rest shape.
void World::detectBodyContacts() {
  bodyContacts_.clear();
  std::vector<BodyId> taking;
  int touching = 0;
  bool self = false;
  for (BodyId id = 0; id < bodies_.size(); ++id) {
    const BodyContactSettings& s = bodyContactSettings_[id];
    if (bodies_[id].state != BodyState::Active || bodies_[id].model->surface.empty() || !(s.bodies || s.self)) continue;
    taking.push_back(id);
    touching += s.bodies;
    self |= s.self;
  }
  if (taking.empty() || (!self && touching < 2)) return;

  const Point* const pred = predicted_.data();
  const Point* const start = local_.data();
  const Body& reference = bodies_[taking.front()];
  const auto sweptBox = [&](Index i, const Vec3& offset, float grow) {
    Box3f box(start[i].pos + offset);
    box.extend(pred[i].pos + offset);
    return Box3f(box.min().array() - grow, box.max().array() + grow);
  };
  contactTriangles_.clear();
  contactBoxes_.clear();
  double extent = 0.0;
  for (BodyId id : taking) {
    const Body& b = bodies_[id];
    const Vec3 offset = offsetBetween(b, reference);
    const float grow = bodyContactSettings_[id].thickness;
    const std::vector<Triangle>& surface = b.model->surface;
    for (Index t = 0; t < surface.size(); ++t) {
      Box3f box = sweptBox(b.firstParticle + surface[t][0], offset, grow);
      box.extend(sweptBox(b.firstParticle + surface[t][1], offset, grow));
      box.extend(sweptBox(b.firstParticle + surface[t][2], offset, grow));
      contactTriangles_.push_back({id, t});
      contactBoxes_.push_back(box);
      if (const float size = box.sizes().maxCoeff(); std::isfinite(size)) extent += size;
    }
  }
  // Cells the size of a typical triangle's box: a vertex's box meets a few cells, a triangle's a few.
  const float cell = std::max(float(extent / double(contactBoxes_.size())), 1e-6f);
  contactHash_.build(contactBoxes_, cell);
  contactSeen_.assign(contactBoxes_.size(), std::numeric_limits<Index>::max());

  for (BodyId a : taking) {
    const Body& body = bodies_[a];
    const BodyContactSettings& sa = bodyContactSettings_[a];
    const ContactSurface& surfaceA = contactSurfaces_[a];
    const Vec3 offsetA = offsetBetween(body, reference);
    for (Index v : surfaceA.vertices) {
      const Index i = body.firstParticle + v;
      const Box3f box = sweptBox(i, offsetA, sa.thickness);
      const std::size_t first = bodyContacts_.size();
      const float vertexMotion = (pred[i].pos - start[i].pos).norm();
      contactHash_.query(box, [&](Index item) {
        if (contactSeen_[item] == i) return;
        contactSeen_[item] = i;
        const BodyId bId = contactTriangles_[item].body;
        const BodyContactSettings& sb = bodyContactSettings_[bId];
        if (a == bId ? !sa.self : !(sa.bodies && sb.bodies && pairContact(a, bId))) return;
        if (!box.intersects(contactBoxes_[item])) return;
        const Body& other = bodies_[bId];
        const Triangle& tri = other.model->surface[contactTriangles_[item].triangle];
        const float gap = sa.thickness + sb.thickness;
        if (a == bId) {
          const Index* const n = surfaceA.neighbours.data();
          const auto near = [&](Index c) {
            return c == v || std::binary_search(n + surfaceA.neighbourStart[v], n + surfaceA.neighbourStart[v + 1], c);
          };
          if (near(tri[0]) || near(tri[1]) || near(tri[2])) return;
          const std::vector<Vec3>& rest = body.model->restPositions;
          const std::array<float, 3> w = closestPointOnTriangle(rest[v], rest[tri[0]], rest[tri[1]], rest[tri[2]]);
          if ((rest[v] - (w[0] * rest[tri[0]] + w[1] * rest[tri[1]] + w[2] * rest[tri[2]])).norm() <= gap) return;
        }
        const Index corner[3] = {other.firstParticle + tri[0], other.firstParticle + tri[1],
                                 other.firstParticle + tri[2]};
        if (pred[i].w == 0.0f && pred[corner[0]].w == 0.0f && pred[corner[1]].w == 0.0f && pred[corner[2]].w == 0.0f)
          return;
        const Vec3 offset = offsetBetween(other, body);
        const std::optional<VertexTriangleTouch> touch =
            touchVertexTriangle(start[i].pos, start[corner[0]].pos + offset, start[corner[1]].pos + offset,
                                start[corner[2]].pos + offset, contactSurfaces_[bId].closed);
        if (!touch) return;
        float motion = vertexMotion;
        for (Index c : corner) motion = std::max(motion, vertexMotion + (pred[c].pos - start[c].pos).norm());
        if (!(touch->distance >= -gap && touch->distance <= gap + motion)) return;
        bodyContacts_.push_back({i,
                                 {corner[0], corner[1], corner[2]},
                                 contactSurfaces_[bId].firstKey + contactTriangles_[item].triangle,
                                 offset,
                                 touch->normal,
                                 touch->b,
                                 gap,
                                 sa.compliance + sb.compliance,
                                 std::sqrt(sa.staticFriction * sb.staticFriction),
                                 std::sqrt(sa.dynamicFriction * sb.dynamicFriction)});
      });
      // In particle order, then by triangle: the order the warm start matches contacts in.
      std::sort(bodyContacts_.begin() + std::ptrdiff_t(first), bodyContacts_.end(),
                [](const BodyContact& x, const BodyContact& y) { return x.triangle < y.triangle; });
    }
  }
}

// By the leader, after the other contacts: each contact's plane, then its friction.
void World::solveBodyContacts(float invH) {
  Point* const pred = predicted_.data();
  const Point* const start = local_.data();
  for (std::size_t c = 0; c < bodyContacts_.size(); ++c) {
    const BodyContact& con = bodyContacts_[c];
    Point& p = pred[con.particle];
    std::array<Point, 3> x;
    std::array<Vec3, 3> x0;
    for (std::size_t k = 0; k < 3; ++k) {
      x[k] = {pred[con.corner[k]].pos + con.offset, pred[con.corner[k]].w};
      x0[k] = start[con.corner[k]].pos + con.offset;
    }
    const VertexTriangleCorrection r = solveVertexTriangleContact(
        p, x, con, bodyContactLambda_[c], XpbdCoefficients::make(con.compliance, 0.0f, invH));
    bodyContactLambda_[c] += r.dLambda;
    p.pos += r.dp;
    for (std::size_t k = 0; k < 3; ++k) x[k].pos += r.dx[k];
    const Vec3 friction = vertexTriangleFriction(p, start[con.particle].pos, x, x0, con, bodyContactLambda_[c],
                                                 bodyContactFrictionLambda_[c]);
    bodyContactFrictionLambda_[c] += friction;
    p.pos += p.w * friction;
    for (std::size_t k = 0; k < 3; ++k)
      pred[con.corner[k]].pos = x[k].pos - con.offset - (x[k].w * con.b[k]) * friction;
  }
}

float World::deepestPenetration() const {
  float deepest = 0.0f;
  for (const BodyContact& con : bodyContacts_) {
    Vec3 q = Vec3::Zero();
    for (std::size_t k = 0; k < 3; ++k) q += con.b[k] * (local_[con.corner[k]].pos + con.offset);
    deepest = std::max(deepest, -con.normal.dot(local_[con.particle].pos - q));
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
    const Vec3 push = bodyContactLambda_[c] * con.normal + bodyContactFrictionLambda_[c];
    if (particleBody_[con.particle] == on && particleBody_[con.corner[0]] == by) sum += push;
    if (particleBody_[con.corner[0]] == on && particleBody_[con.particle] == by) sum -= push;
  }
  return sum / (h * h);
}

}  // namespace vrd
