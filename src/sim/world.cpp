#include "vrdeform/sim/world.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <type_traits>
#include <utility>

#include "lane_sweeps.h"
#include "solver_team.h"
#include "vrdeform/error.h"

namespace vrd {
namespace {

constexpr Index kNoParticle = std::numeric_limits<Index>::max();
constexpr float kFingertipSkin = 0.05f;  // fingertip contact candidates reach 5% beyond the radius

void checkFinite(const Vec3& v, const char* what) {
  if (!isFinite(v)) throw Error(fmt::format("{}: non-finite value ({}, {}, {})", what, v.x(), v.y(), v.z()));
}

void checkCompliance(float compliance, const char* what) {
  if (!(std::isfinite(compliance) && compliance >= 0.0f))
    throw Error(fmt::format("{}: compliance must be finite and >= 0, got {}", what, compliance));
}

void checkContactMode(FingertipContactMode mode, const char* what) {
  if (mode != FingertipContactMode::Particles && mode != FingertipContactMode::Triangles)
    throw Error(fmt::format("{}: unknown fingertip contact mode {}", what, int(mode)));
}

// A body's length for its residuals: the mean rest edge of its tets, else of its distance
// constraints, else 1 cm (a body of free particles).
float meanRestEdge(const BodyModel& m) {
  double sum = 0.0;
  std::size_t count = 0;
  const auto& x = m.restPositions;
  for (const Tet& t : m.tets)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) sum += double((x[t[a]] - x[t[b]]).norm()), ++count;
  if (count == 0)
    for (const DistanceConstraint& c : m.distance) sum += double(c.restLength), ++count;
  return count > 0 && sum > 0.0 ? float(sum / double(count)) : 0.01f;
}

// Zeroes a body's multipliers (Algorithm 1, line 9): a team member its share of each array.
void clearMultipliers(Body& b, const SolverTeam& team = SolverTeam{}) {
  const auto clear = [&]<typename T>(T* values, std::size_t count, const T& zero) {
    const auto [first, last] = team.share(0, count, 16);
    std::fill(values + first, values + last, zero);
  };
  clear(b.distanceLambda.data(), b.distanceLambda.size(), 0.0f);
  clear(b.volumeLambda.data(), b.volumeLambda.size(), 0.0f);
  clear(b.strainLambda.data(), kStrainComponents * b.strainLambda.size(), 0.0f);
  clear(b.bendLambda.data(), b.bendLambda.size(), 0.0f);
  clear(b.shapeMatchLambda.data(), b.shapeMatchLambda.size(), Vec3(Vec3::Zero()));
}

// A body-frame position in the world, and back, through the frame's origin in double.
Vec3 worldOf(const Vec3d& origin, const Vec3& local) { return (origin + local.cast<double>()).cast<float>(); }
Vec3 frameOf(const Vec3d& origin, const Vec3& world) { return (world.cast<double>() - origin).cast<float>(); }

// Where a frame's origin should move (relative to it): to the centre of mass of the moving
// particles (of all of them when none moves), snapped to twice the float spacing of the farthest
// coordinate, so that the move is exact for the particles far from the centre.
Vec3 centreOfMass(std::span<const Point> x) {
  Vec3d sum = Vec3d::Zero(), all = Vec3d::Zero();
  double mass = 0.0;
  float extent = 0.0f;
  for (const Point& p : x) {
    extent = std::max(extent, p.pos.cwiseAbs().maxCoeff());
    all += p.pos.cast<double>();
    if (p.w > 0.0f) sum += p.pos.cast<double>() / double(p.w), mass += 1.0 / double(p.w);
  }
  if (x.empty() || !(extent > 0.0f) || !std::isfinite(extent)) return Vec3::Zero();
  const Vec3d centre = mass > 0.0 ? Vec3d(sum / mass) : Vec3d(all / double(x.size()));
  const double grid = std::ldexp(1.0, std::ilogb(extent) - 22);
  return (centre / grid).array().round().matrix().cast<float>() * float(grid);
}

}  // namespace

World::World(const SolverSettings& settings) { setSettings(settings); }
World::TeamSlot::TeamSlot(const TeamSlot&) {}
World::TeamSlot::TeamSlot(TeamSlot&&) noexcept = default;
World::TeamSlot& World::TeamSlot::operator=(const TeamSlot&) { return *this; }
World::TeamSlot& World::TeamSlot::operator=(TeamSlot&&) noexcept = default;
World::TeamSlot::~TeamSlot() = default;

void World::setSettings(const SolverSettings& settings) {
  validateSolverSettings(settings);
  // The multipliers scale with h^2: a warm start from another substep size would be wrong.
  const bool cold = settings.timeStep != settings_.timeStep || settings.substeps != settings_.substeps ||
                    settings.warmStart != settings_.warmStart;
  settings_ = settings;
  if (cold)
    for (BodyId id = 0; id < bodies_.size(); ++id) coldStart(id);
}

void World::coldStart(BodyId id) { clearMultipliers(bodies_[id]); }

BodyId World::addBody(std::shared_ptr<const BodyModel> model, const Vec3& translation, const Quat& rotation) {
  if (!model) throw Error("addBody: no model");
  validateModel(*model);
  checkFinite(translation, "addBody translation");
  if (!(rotation.coeffs().allFinite() && std::abs(rotation.norm() - 1.0f) < 1e-3f))
    throw Error("addBody: rotation must be a unit quaternion");

  Body body;
  body.model = model;
  body.firstParticle = Index(particles_.size());
  body.particleCount = Index(model->particleCount());
  body.distanceLambda.assign(model->distance.size(), 0.0f);
  body.volumeLambda.assign(model->volume.size(), 0.0f);
  body.strainLambda.assign(model->strain.size());
  body.bendLambda.assign(model->bend.size(), 0.0f);
  body.tetsPaired = !model->strain.empty() && model->strain.size() == model->volume.size() &&
                    std::equal(model->strain.begin(), model->strain.end(), model->volume.begin(),
                               [](const StrainConstraint& s, const VolumeConstraint& v) {
                                 return std::equal(std::begin(s.i), std::end(s.i), std::begin(v.i));
                               });
  const ConstraintDamping& tau = model->damping;
  if (!model->strain.empty() && (tau.strainStretch > 0.0f || tau.strainShear > 0.0f || tau.volume > 0.0f))
    body.startDeformation.assign(9 * model->strain.size(), 0.0f);
  body.shapeMatchLambda.assign(model->shapeMatching ? model->particleCount() : 0, Vec3::Zero());
  body.lengthScale = meanRestEdge(*model);
  body.shapeMatchRotation = rotation.cast<double>();
  // The frame: the rotated rest shape about its centre of mass, which the translation places.
  std::vector<Point> placed;
  for (std::size_t i = 0; i < model->particleCount(); ++i)
    placed.push_back({rotation * model->restPositions[i], model->invMass[i]});
  const Vec3 centre = centreOfMass(placed);
  body.origin = body.initialOrigin = translation.cast<double>() + centre.cast<double>();
  const BodyId id = BodyId(bodies_.size());
  for (Point& p : placed) {
    p.pos -= centre;
    body.initialPositions.push_back(p.pos);
    local_.push_back(p);
    predicted_.push_back(p);
    inertial_.push_back(p);
    particles_.x.push_back({worldOf(body.origin, p.pos), p.w});
    particles_.v.push_back(Vec3::Zero());
    particles_.force.push_back(Vec3::Zero());
    particleBody_.push_back(id);
  }
  bodies_.push_back(std::move(body));
  contactSurfaces_.push_back(contactSurfaceOf(*model));
  if (id > 0) {
    const ContactSurface& before = contactSurfaces_[id - 1];
    contactSurfaces_[id].firstTriangleKey = before.firstTriangleKey + Index(bodies_[id - 1].model->surface.size());
    contactSurfaces_[id].firstEdgeKey = before.firstEdgeKey + Index(before.edges.size());
  }
  bodyContactSettings_.emplace_back();
  frameColliders();
  frameFingertips();
  return id;
}

void World::resetBody(BodyId id) {
  Body& b = bodies_.at(id);
  b.origin = b.initialOrigin;
  for (Index i = 0; i < b.particleCount; ++i) {
    const Index g = b.firstParticle + i;
    local_[g].pos = predicted_[g].pos = b.initialPositions[i];
    particles_.x[g].pos = worldOf(b.origin, b.initialPositions[i]);
    particles_.v[g].setZero();
  }
  frameColliders();
  frameFingertips();
  coldStart(id);
  b.shapeMatchRotation = Eigen::Quaterniond::Identity();
  b.state = BodyState::Active;
}

void World::setInverseMass(Index particle, float w) {
  if (particle >= particles_.size()) throw Error(fmt::format("setInverseMass: no particle {}", particle));
  if (!(std::isfinite(w) && w >= 0.0f))
    throw Error(fmt::format("setInverseMass: inverse mass must be >= 0, got {}", w));
  particles_.x[particle].w = local_[particle].w = predicted_[particle].w = w;
}

void World::setExternalForce(BodyId id, const Vec3& force, const Vec3& perKg) {
  checkFinite(force, "setExternalForce");
  checkFinite(perKg, "setExternalForce (per kg)");
  const Body& b = bodies_.at(id);
  for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i) {
    const float w = particles_.x[i].w;
    particles_.force[i] = w > 0.0f ? Vec3(force + perKg / w) : force;
  }
}

AttachmentId World::attach(Index particle, const Vec3& target, float compliance, const Vec3& axes, float damping) {
  if (particle >= particles_.size()) throw Error(fmt::format("attach: no particle {}", particle));
  checkFinite(target, "attach target");
  checkCompliance(compliance, "attach");
  if (!((axes.array() == 0.0f) || (axes.array() == 1.0f)).all()) throw Error("attach: axes must be 0 or 1 each");
  if (!(std::isfinite(damping) && damping >= 0.0f)) throw Error("attach: damping must be finite and >= 0");
  const Attachment a{particle, target, target, axes, compliance, compliance * damping};
  for (std::size_t id = 0; id < attachments_.size(); ++id)
    if (attachments_[id].particle == kNoParticle) {
      attachments_[id] = a;
      attachmentLambda_[id].setZero();
      return AttachmentId(id);
    }
  attachments_.push_back(a);
  attachmentLambda_.push_back(Vec3::Zero());
  return AttachmentId(attachments_.size() - 1);
}

void World::moveAttachment(AttachmentId id, const Vec3& goal) {
  checkFinite(goal, "moveAttachment goal");
  attachments_.at(id).goal = goal;
}

void World::detach(AttachmentId id) {
  attachments_.at(id).particle = kNoParticle;
  attachmentLambda_[id].setZero();
}

Vec3 World::attachmentForce(AttachmentId id) const {
  const float h = substepSize();
  return attachmentLambda_.at(id) / (h * h);
}

ColliderId World::addCollider(const Collider& collider) {
  validateCollider(collider);
  colliders_.push_back(collider);
  frameColliders();
  return ColliderId(colliders_.size() - 1);
}

FingertipId World::addFingertip(const Vec3& center, float radius, float compliance, FingertipContactMode mode) {
  checkFinite(center, "addFingertip centre");
  if (!(std::isfinite(radius) && radius > 0.0f))
    throw Error(fmt::format("addFingertip: radius must be positive, got {}", radius));
  checkCompliance(compliance, "addFingertip");
  checkContactMode(mode, "addFingertip");
  fingertips_.push_back({center, center, radius, compliance, true, mode, {}, center});
  frameFingertips();
  return FingertipId(fingertips_.size() - 1);
}

void World::moveFingertip(FingertipId id, const Vec3& goal) {
  checkFinite(goal, "moveFingertip goal");
  fingertips_.at(id).goal = goal;
}

void World::setFingertipEnabled(FingertipId id, bool enabled) { fingertips_.at(id).enabled = enabled; }

void World::setFingertipContactMode(FingertipId id, FingertipContactMode mode) {
  checkContactMode(mode, "setFingertipContactMode");
  fingertips_.at(id).mode = mode;
}

void World::setFingertipFriction(FingertipId id, const FingertipFriction& friction) {
  if (!(std::isfinite(friction.staticFriction) && friction.staticFriction >= 0.0f &&
        std::isfinite(friction.dynamicFriction) && friction.dynamicFriction >= 0.0f))
    throw Error(fmt::format("setFingertipFriction: coefficients must be finite and >= 0, got {} and {}",
                            friction.staticFriction, friction.dynamicFriction));
  fingertips_.at(id).friction = friction;
}

Vec3 World::fingertipForce(FingertipId id) const {
  const float h = substepSize();
  Vec3 force = Vec3::Zero();
  const Fingertip& f = fingertips_.at(id);
  for (std::size_t c = 0; c < fingertipContacts_.size(); ++c)
    if (const FingertipContact& con = fingertipContacts_[c]; con.fingertip == id) {
      const Vec3 centre = frameFingertip(particleBody_[con.particle], id).center;
      force += fingertipLambda_[c] * evalSphereContact(local_[con.particle].pos, centre, f.radius).n +
               fingertipFrictionLambda_[c];
    }
  for (std::size_t c = 0; c < fingertipTriangleContacts_.size(); ++c)
    if (fingertipTriangleContacts_[c].fingertip == id)
      for (const Vec3& impulse : fingertipTriangleImpulse_[c]) force += impulse;
  return force / (h * h);
}

std::size_t World::fingertipContactCount(FingertipId id) const {
  std::size_t count = 0;
  for (std::size_t c = 0; c < fingertipContacts_.size(); ++c)
    count += fingertipContacts_[c].fingertip == id && fingertipLambda_[c] > 0.0f;
  for (std::size_t c = 0; c < fingertipTriangleContacts_.size(); ++c)
    count += fingertipTriangleContacts_[c].fingertip == id && fingertipTriangleLambda_[c] > 0.0f;
  return count;
}

float World::fingertipLambdaSum(FingertipId id) const {
  float sum = 0.0f;
  for (std::size_t c = 0; c < fingertipContacts_.size(); ++c)
    if (fingertipContacts_[c].fingertip == id) sum += std::abs(fingertipLambda_[c]);
  for (std::size_t c = 0; c < fingertipTriangleContacts_.size(); ++c)
    if (fingertipTriangleContacts_[c].fingertip == id) sum += std::abs(fingertipTriangleLambda_[c]);
  return sum;
}

std::vector<SimEvent> World::takeEvents() { return std::exchange(events_, {}); }

void World::step() {
  report_ = StepReport{};
  report_.step = stepCount_;
  residualCount_.fill(0);
  ingest();
  warm_ = settings_.warmStart;
  // A team pays only for a body big enough to be cut in groups (body_model.cpp): a smaller array is
  // swept by one member anyway, and the others would only wait at its barriers.
  const bool cut = std::any_of(bodies_.begin(), bodies_.end(), [](const Body& b) {
    return b.state == BodyState::Active && !(b.model->tetGroups.empty() && b.model->distanceGroups.empty());
  });
  const int threads = solverThreads(settings_);
  if (threads > 1 && cut) {
    std::unique_ptr<ThreadTeam>& team = team_.team;
    if (!team || team->size() != threads) team = std::make_unique<ThreadTeam>(threads);
    const bool onTeam = !settings_.threadsFallBack || team->choice().useTeam();
    const auto start = std::chrono::steady_clock::now();
    if (onTeam) {
      memberContacts_.resize(std::size_t(threads));
      memberFinite_.resize(std::size_t(threads) * bodies_.size());
      team->run([this](const SolverTeam& member) { substeps(member); });
    } else {
      memberFinite_.resize(bodies_.size());
      substeps(SolverTeam{});
    }
    if (settings_.threadsFallBack)
      team->choice().record(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  } else {
    memberFinite_.resize(bodies_.size());
    substeps(SolverTeam{});
  }
  for (std::size_t s = 0; s < kStageCount; ++s)
    if (residualCount_[s] > 0)
      report_.residuals[s] = {std::sqrt(residualSumSq_[s] / double(residualCount_[s])), residualMax_[s]};
  const auto pushed = [](float l) { return l > 0.0f; };
  report_.colliderContacts =
      std::size_t(std::count_if(contactNormalLambda_.begin(), contactNormalLambda_.end(), pushed));
  report_.fingertipContacts =
      std::size_t(std::count_if(fingertipLambda_.begin(), fingertipLambda_.end(), pushed) +
                  std::count_if(fingertipTriangleLambda_.begin(), fingertipTriangleLambda_.end(), pushed));
  report_.bodyContacts = std::size_t(std::count_if(bodyContactLambda_.begin(), bodyContactLambda_.end(), pushed));
  report_.deepestPenetration = deepestPenetration();
  publish();
  ++stepCount_;
}

// A world position that differs from the one published is the caller's: it moves the particle,
// and its body starts cold (the last substep's moves belong to another shape).
void World::ingest() {
  for (BodyId id = 0; id < bodies_.size(); ++id) {
    const Body& b = bodies_[id];
    bool moved = false;
    for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i) {
      const Point& x = particles_.x[i];
      if (x.pos != worldOf(b.origin, local_[i].pos)) local_[i].pos = frameOf(b.origin, x.pos), moved = true;
      local_[i].w = predicted_[i].w = x.w;
    }
    if (moved) coldStart(id);
  }
}

void World::frameColliders() {
  frameColliders_.clear();
  for (const Body& b : bodies_)
    for (Collider c : colliders_) {
      c.center = frameOf(b.origin, c.center);
      frameColliders_.push_back(c);
    }
}

// Between steps the fingertips are where they are; in a step's substep, at `from` and `to` of the
// way from the step's start to their goals (double, from fingertipFrom_).
void World::frameFingertips(double from, double to) {
  const bool moving = fingertipFrom_.size() == fingertips_.size();
  const auto along = [&](std::size_t f, double t) {
    const Vec3d start = fingertipFrom_[f];
    return Vec3d(start + t * (fingertips_[f].goal.cast<double>() - start));
  };
  if (moving)
    for (std::size_t f = 0; f < fingertips_.size(); ++f) {
      fingertips_[f].substepStart = along(f, from).cast<float>();
      fingertips_[f].center = along(f, to).cast<float>();
    }
  frameFingertips_.clear();
  for (const Body& b : bodies_)
    for (std::size_t f = 0; f < fingertips_.size(); ++f) {
      Fingertip tip = fingertips_[f];
      if (moving) {
        tip.center = (along(f, to) - b.origin).cast<float>();
        tip.substepStart = (along(f, from) - b.origin).cast<float>();
      } else {
        tip.center = frameOf(b.origin, tip.center);
        tip.substepStart = frameOf(b.origin, tip.substepStart);
      }
      frameFingertips_.push_back(tip);
    }
}

// Each active body's frame moves to the centre of mass of its moving particles: they move by the
// same (snapped) amount and keep their velocities; a kinematic particle keeps its world position,
// so that one held still does not wander by a rounding each step. Then the world view.
void World::publish() {
  for (Body& b : bodies_) {
    Point* const x = local_.data() + b.firstParticle;
    const Vec3 shift = b.state == BodyState::Active ? centreOfMass({x, b.particleCount}) : Vec3::Zero();
    if (shift != Vec3::Zero()) {
      const Vec3d from = b.origin;
      b.origin += shift.cast<double>();
      for (Index i = 0; i < b.particleCount; ++i)
        x[i].pos = x[i].w > 0.0f ? Vec3(x[i].pos - shift) : frameOf(b.origin, worldOf(from, x[i].pos));
    }
    for (Index i = 0; i < b.particleCount; ++i)
      particles_.x[b.firstParticle + i] = {worldOf(b.origin, x[i].pos), x[i].w};
  }
  frameColliders();  // the contacts' readouts (fingertipForce, ...) compare with the frames' positions
  fingertipFrom_.clear();
  frameFingertips();
}

// Algorithm 1 by a team: each member predicts, detects and finalises its share of the particles,
// and the barriers sit where one member's work reads another's.
void World::substeps(const SolverTeam& team) {
  const int n = settings_.substeps;
  const float h = settings_.substepSize();
  const sweeps::LanePlan plan = sweeps::lanePlan(settings_.simd);
  for (int s = 0; s < n; ++s) {
    if (team.leader()) {
      // Kinematic targets move linearly from where they were to their goals over the step; the
      // fingertips' centres in double from the step's start, so that their frame positions do not
      // depend on where in the world they are.
      const float share = 1.0f / float(n - s);
      for (Attachment& a : attachments_) a.target += share * (a.goal - a.target);
      if (s == 0) {
        fingertipFrom_.clear();
        for (const Fingertip& f : fingertips_) fingertipFrom_.push_back(f.center.cast<double>());
      }
      frameFingertips(double(s) / n, double(s + 1) / n);
    }
    predict(h, team);
    team.barrier();                    // detection reads the fingertips' new centres
    if (warm_) warmStart(plan, team);  // before detection, which sees where it puts them
    detectContacts(team);
    recordSubstepStart(plan, team);  // its closing barrier also closes detection
    // Iterations: all of them, or (adaptive) until the largest correction is within the tolerance.
    const bool adaptive = settings_.tolerance > 0.0f;
    int it = 0;
    while (it < settings_.iterations) {
      const bool measure = adaptive || (settings_.measureResiduals && s + 1 == n && it + 1 == settings_.iterations);
      if (measure && team.leader()) {
        residualSumSq_.fill(0.0);
        residualMax_.fill(0.0);
        residualCount_.fill(0);
      }
      solveIteration(h, plan, team, measure);
      ++it;
      if (adaptive) {
        if (team.leader())
          converged_ = *std::max_element(residualMax_.begin(), residualMax_.end()) < settings_.tolerance;
        team.barrier();  // (the leader writes it again only past the next iteration's barriers)
        if (converged_) break;
      }
    }
    if (team.leader()) report_.iterations += it;
    finalise(h, team);
  }
}

// This member's share of a body's particles: the team cuts all particles at multiples of 64 (cache
// line boundaries of the Points, 16 bytes, and of the velocities, 12 bytes), then clips to the body.
std::pair<Index, Index> World::particlesOf(const Body& b, const SolverTeam& team) const {
  const auto [first, last] = team.share(0, predicted_.size(), 64);
  return {std::max(Index(first), b.firstParticle), std::min(Index(last), b.firstParticle + b.particleCount)};
}

void World::predict(float h, const SolverTeam& team) {
  StageTimer timer(report_.times, Stage::Predict, settings_.timeStages && team.leader());
  const float keep = std::max(0.0f, 1.0f - settings_.linearDamping * h);
  const bool warm = warm_;
  for (const Body& b : bodies_) {
    if (b.state != BodyState::Active) continue;
    for (auto [i, end] = particlesOf(b, team); i < end; ++i) {
      const Point& x = local_[i];
      Vec3& v = particles_.v[i];
      if (x.w > 0.0f) v = keep * v + h * (settings_.gravity + x.w * particles_.force[i]);  // damp, then add forces
      predicted_[i] = {x.pos + h * v, x.w};  // kinematic particles follow their velocity
      if (warm) inertial_[i] = predicted_[i];
    }
  }
}

// Contacts in particle order (bodies are appended, so their particles come in body order): the
// team cuts the lists at particle boundaries (solveWorldConstraints). Each member detects its share
// of the particles into its own lists, and the leader joins them in member order (so in particle
// order) and finds the triangle contacts; the team finds the body contacts together; then each
// member resets its share of the multipliers and goes on to recordSubstepStart, whose barrier
// closes this.
void World::detectContacts(const SolverTeam& team) {
  StageTimer timer(report_.times, Stage::Detect, settings_.timeStages && team.leader());
  MemberContacts* const own = team.leader() ? nullptr : &memberContacts_[std::size_t(team.index)];
  std::vector<ColliderContact>& collider = own ? own->collider : colliderContacts_;
  std::vector<FingertipContact>& fingertip = own ? own->fingertip : fingertipContacts_;
  if (warm_ && team.leader()) {  // kept to carry their multipliers over (resetMultipliers)
    previousColliderContacts_.swap(colliderContacts_);
    previousFingertipContacts_.swap(fingertipContacts_);
    previousTriangleContacts_.swap(fingertipTriangleContacts_);
    previousBodyContacts_.swap(bodyContacts_);
  }
  collider.clear();
  fingertip.clear();
  detectParticleContacts(team, collider, fingertip);
  if (team.leader()) prepareBodyContacts();
  team.barrier();
  if (team.leader()) {
    for (int k = 1; k < team.size; ++k) {
      const MemberContacts& other = memberContacts_[std::size_t(k)];
      colliderContacts_.insert(colliderContacts_.end(), other.collider.begin(), other.collider.end());
      fingertipContacts_.insert(fingertipContacts_.end(), other.fingertip.begin(), other.fingertip.end());
    }
    detectTriangleContacts();
  }
  detectBodyContacts(team);
  resetMultipliers(team);
}

void World::detectParticleContacts(const SolverTeam& team, std::vector<ColliderContact>& colliderContacts,
                                   std::vector<FingertipContact>& fingertipContacts) const {
  const bool tips = std::any_of(fingertips_.begin(), fingertips_.end(), [](const Fingertip& f) {
    return f.enabled && f.mode == FingertipContactMode::Particles;
  });
  for (BodyId id = 0; id < bodies_.size(); ++id) {
    const Body& b = bodies_[id];
    if (b.state != BodyState::Active) continue;
    const float radius = b.model->particleRadius;
    for (auto [i, end] = particlesOf(b, team); i < end; ++i) {
      const Point& p = predicted_[i];
      if (p.w == 0.0f) continue;
      // Anything the particle could reach in this substep: its predicted motion as margin. The
      // contacts are inequalities, so candidates that stay clear cost a check and do nothing.
      // distance < radius + motion, squared where both sides are positive (no square root).
      const float motion2 = (p.pos - local_[i].pos).squaredNorm();
      for (Index c = 0; c < colliders_.size(); ++c)
        if (const float gap = closestSurface(frameCollider(id, c), p.pos).distance - radius;
            gap < 0.0f || gap * gap < motion2)
          colliderContacts.push_back({i, c, radius});
      if (!tips) continue;
      // Eq. 36: N(r) from the predicted positions, widened by the same margin plus a skin, so that
      // a particle resting on the fingertip is not dropped when its prediction lands just outside.
      const float motion = std::sqrt(motion2);
      for (Index f = 0; f < fingertips_.size(); ++f) {
        const Fingertip& tip = frameFingertip(id, f);
        if (!tip.enabled || tip.mode != FingertipContactMode::Particles) continue;
        const float reach = tip.radius * (1.0f + kFingertipSkin) + motion;
        if ((p.pos - tip.center).squaredNorm() <= reach * reach) fingertipContacts.push_back({i, f});
      }
    }
  }
}

// Fingertips in Triangles mode against the active bodies' surface triangles, from the predicted
// positions (eq. 36 with the closest point of a triangle in place of a particle). Triangles whose
// corners are all kinematic cannot be pushed and are skipped.
void World::detectTriangleContacts() {
  fingertipTriangleContacts_.clear();
  if (std::none_of(fingertips_.begin(), fingertips_.end(),
                   [](const Fingertip& f) { return f.enabled && f.mode == FingertipContactMode::Triangles; }))
    return;
  const Point* const pred = predicted_.data();
  const Point* const start = local_.data();
  for (BodyId id = 0; id < bodies_.size(); ++id) {
    const Body& b = bodies_[id];
    if (b.state != BodyState::Active) continue;
    for (const Triangle& t : b.model->surface) {
      const Index i[3] = {b.firstParticle + t[0], b.firstParticle + t[1], b.firstParticle + t[2]};
      const Point &p0 = pred[i[0]], &p1 = pred[i[1]], &p2 = pred[i[2]];
      if (p0.w == 0.0f && p1.w == 0.0f && p2.w == 0.0f) continue;
      // The same margin as for particles: the farthest predicted motion of a corner, plus the skin.
      const float motion =
          std::sqrt(std::max({(p0.pos - start[i[0]].pos).squaredNorm(), (p1.pos - start[i[1]].pos).squaredNorm(),
                              (p2.pos - start[i[2]].pos).squaredNorm()}));
      const Vec3 lo = p0.pos.cwiseMin(p1.pos).cwiseMin(p2.pos), hi = p0.pos.cwiseMax(p1.pos).cwiseMax(p2.pos);
      for (Index f = 0; f < fingertips_.size(); ++f) {
        const Fingertip& tip = frameFingertip(id, f);
        if (!tip.enabled || tip.mode != FingertipContactMode::Triangles) continue;
        const float reach = tip.radius * (1.0f + kFingertipSkin) + motion;
        if (((tip.center.array() + reach) < lo.array()).any() || ((tip.center.array() - reach) > hi.array()).any())
          continue;  // the triangle's box is out of reach
        const TriangleContactEval<float> e =
            evalFingertipTriangleContact(p0.pos, p1.pos, p2.pos, tip.center, tip.radius);
        if (!e.n.isZero() && e.C + tip.radius <= reach) fingertipTriangleContacts_.push_back({{i[0], i[1], i[2]}, f});
      }
    }
  }
}

namespace {

// For each contact of `now`, the index of the same contact in `before` (or npos): both lists
// ascending in `key` (detection's order: by particle and then by collider or fingertip; body
// contacts by BodyContact::key).
template <typename Contact, typename Key>
std::vector<std::size_t> sameContacts(const std::vector<Contact>& before, const std::vector<Contact>& now, Key key) {
  std::vector<std::size_t> out(now.size(), std::string::npos);
  for (std::size_t i = 0, j = 0; i < now.size(); ++i) {
    while (j < before.size() && key(before[j]) < key(now[i])) ++j;
    if (j < before.size() && key(before[j]) == key(now[i])) out[i] = j;
  }
  return out;
}

// A contact list's multipliers for the contacts now detected: each carried over from the same
// contact in the last substep, else zero.
template <typename T>
void carry(std::vector<T>& lambdas, const std::vector<std::size_t>& from, const T& zero) {
  std::vector<T> out(from.size(), zero);
  for (std::size_t i = 0; i < from.size(); ++i)
    if (from[i] != std::string::npos) out[i] = lambdas[from[i]];
  lambdas = std::move(out);
}

}  // namespace

// Whether the warm start moved every particle by at most a quarter of its body's mean rest edge. A
// light particle carrying a large force (a body hanging from one held corner, a light, nearly
// incompressible body on a coarse substep, a body thrown about) is moved farther by its forces'
// w h^2 f, and Gauss-Seidel from there can diverge: such a substep starts cold.
bool World::warmPushesFit() const {
  for (const Body& b : bodies_) {
    if (b.state != BodyState::Active) continue;
    const float limit2 = 0.0625f * b.lengthScale * b.lengthScale;
    for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i)
      if ((predicted_[i].pos - inertial_[i].pos).squaredNorm() > limit2) return false;
  }
  return true;
}

// The bodies' multipliers by the team; the contacts' and attachments' (once detected) by the leader.
// With a warm start, a contact found again keeps its multipliers and pushes its particles as it did
// in the last substep, so that the pushes balance the bodies' (warmStart): a fingertip held still
// against a body at rest leaves it where it was, whatever the number of iterations.
void World::resetMultipliers(const SolverTeam& team) {
  if (!warm_)
    for (Body& b : bodies_) clearMultipliers(b, team);

  if (!team.leader()) return;
  if (warm_) {
    // Each push along the contact's direction at the inertial predictions, where the bodies' warm
    // start takes its gradients: at rest, the two cancel.
    Point* const pred = predicted_.data();
    const Point* const start = inertial_.data();
    for (std::size_t a = 0; a < attachments_.size(); ++a)  // C = x - target: grad C^T lambda is lambda
      if (const Index p = attachments_[a].particle; p != kNoParticle) pred[p].pos += pred[p].w * attachmentLambda_[a];
    const std::vector<std::size_t> collider =
        sameContacts(previousColliderContacts_, colliderContacts_, [](const ColliderContact& c) {
          return std::pair{c.particle, c.collider};
        });
    carry(contactNormalLambda_, collider, 0.0f);
    carry(contactFrictionLambda_, collider, Vec3(Vec3::Zero()));
    for (std::size_t c = 0; c < colliderContacts_.size(); ++c) {
      const ColliderContact& con = colliderContacts_[c];
      Point& q = pred[con.particle];
      const Vec3 n =
          closestSurface(frameCollider(particleBody_[con.particle], con.collider), start[con.particle].pos).normal;
      q.pos += q.w * (contactNormalLambda_[c] * n + contactFrictionLambda_[c]);
    }
    const std::vector<std::size_t> tip =
        sameContacts(previousFingertipContacts_, fingertipContacts_, [](const FingertipContact& c) {
          return std::pair{c.particle, c.fingertip};
        });
    carry(fingertipLambda_, tip, 0.0f);
    carry(fingertipFrictionLambda_, tip, Vec3(Vec3::Zero()));
    for (std::size_t c = 0; c < fingertipContacts_.size(); ++c) {
      const FingertipContact& con = fingertipContacts_[c];
      const Fingertip& f = frameFingertip(particleBody_[con.particle], con.fingertip);
      Point& q = pred[con.particle];
      const Vec3 n = evalSphereContact(start[con.particle].pos, f.center, f.radius).n;
      q.pos += q.w * (fingertipLambda_[c] * n + fingertipFrictionLambda_[c]);
    }
    std::vector<std::size_t> triangle(fingertipTriangleContacts_.size(), std::string::npos);
    const auto sameTriangle = [](const FingertipTriangleContact& a, const FingertipTriangleContact& b) {
      return a.fingertip == b.fingertip && std::equal(std::begin(a.i), std::end(a.i), std::begin(b.i));
    };
    for (std::size_t c = 0; c < triangle.size(); ++c)  // few: those under the fingertips
      for (std::size_t d = 0; d < previousTriangleContacts_.size(); ++d)
        if (sameTriangle(fingertipTriangleContacts_[c], previousTriangleContacts_[d])) triangle[c] = d;
    carry(fingertipTriangleLambda_, triangle, 0.0f);
    carry(fingertipTriangleFrictionLambda_, triangle, Vec3(Vec3::Zero()));
    fingertipTriangleImpulse_.assign(fingertipTriangleContacts_.size(), {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()});
    for (std::size_t c = 0; c < fingertipTriangleContacts_.size(); ++c) {
      if (fingertipTriangleLambda_[c] == 0.0f) continue;
      const FingertipTriangleContact& con = fingertipTriangleContacts_[c];
      const Fingertip& f = frameFingertip(particleBody_[con.i[0]], con.fingertip);
      const TriangleContactEval<float> e = evalFingertipTriangleContact(start[con.i[0]].pos, start[con.i[1]].pos,
                                                                        start[con.i[2]].pos, f.center, f.radius);
      for (int k = 0; k < 3; ++k) {  // corner k: b_k (-n lambda + lambda_t), as solveWorldConstraints pushes
        fingertipTriangleImpulse_[c][k] =
            e.b[k] * (fingertipTriangleFrictionLambda_[c] - fingertipTriangleLambda_[c] * e.n);
        pred[con.i[k]].pos += pred[con.i[k]].w * fingertipTriangleImpulse_[c][k];
      }
    }
    carryBodyContacts();
    if (warmPushesFit()) return;
    // Too far for a guess: this substep starts cold, from the inertial predictions.
    ++report_.coldSubsteps;
    for (Body& b : bodies_) {
      if (b.state != BodyState::Active) continue;
      std::copy_n(inertial_.begin() + b.firstParticle, b.particleCount, predicted_.begin() + b.firstParticle);
      clearMultipliers(b);
    }
  }
  std::fill(attachmentLambda_.begin(), attachmentLambda_.end(), Vec3::Zero());
  contactNormalLambda_.assign(colliderContacts_.size(), 0.0f);
  contactFrictionLambda_.assign(colliderContacts_.size(), Vec3::Zero());
  fingertipLambda_.assign(fingertipContacts_.size(), 0.0f);
  fingertipFrictionLambda_.assign(fingertipContacts_.size(), Vec3::Zero());
  fingertipTriangleLambda_.assign(fingertipTriangleContacts_.size(), 0.0f);
  fingertipTriangleFrictionLambda_.assign(fingertipTriangleContacts_.size(), Vec3::Zero());
  fingertipTriangleImpulse_.assign(fingertipTriangleContacts_.size(), {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()});
  bodyContactLambda_.assign(bodyContacts_.size(), 0.0f);
  bodyContactFrictionLambda_.assign(bodyContacts_.size(), Vec3::Zero());
}

// Body contacts found again keep their multipliers and push as they did, along their contact
// planes (fixed over a substep, so the inertial predictions' gradients are the solver's).
void World::carryBodyContacts() {
  const std::vector<std::size_t> same =
      sameContacts(previousBodyContacts_, bodyContacts_, [](const BodyContact& c) { return c.key; });
  carry(bodyContactLambda_, same, 0.0f);
  carry(bodyContactFrictionLambda_, same, Vec3(Vec3::Zero()));
  Point* const pred = predicted_.data();
  for (std::size_t c = 0; c < bodyContacts_.size(); ++c) {
    const BodyContact& con = bodyContacts_[c];
    const Vec3 push = bodyContactLambda_[c] * con.normal + bodyContactFrictionLambda_[c];
    for (std::size_t k = 0; k < 4; ++k) pred[con.particle[k]].pos += (pred[con.particle[k]].w * con.weight[k]) * push;
  }
}

namespace {

// Shape matching cuts a body's n particles into `runs` runs (one ShapeMatchSums each), run k from
// n k / runs; each member of the team takes consecutive runs: these.
std::pair<std::size_t, std::size_t> shapeMatchRuns(std::size_t runs, const SolverTeam& team) {
  return {runs * std::size_t(team.index) / std::size_t(team.size),
          runs * std::size_t(team.index + 1) / std::size_t(team.size)};
}

// Eqs. 25-27 for a body's particles `p` by a team: each member sums its runs (in lanes from each
// run's first particle, so that any team adds the same terms in the same order), then every member
// adds all runs in order and finds the same frame. `rotation` warm-starts the extraction and
// receives the result. The caller's next barrier must come before the sums are written again.
ShapeMatchFrame shapeMatchFrameOf(const ShapeMatchModel& sm, const Point* p, std::span<ShapeMatchSums> sums,
                                  const sweeps::LaneSweeps& lanes, const SolverTeam& team,
                                  Eigen::Quaterniond& rotation) {
  const std::size_t runs = sums.size(), n = sm.restOffsets.size();
  const auto [first, last] = shapeMatchRuns(runs, team);
  for (std::size_t k = first; k < last; ++k)
    lanes.shapeMatchSums(p, sm.restOffsets.data(), sm.mass.data(), n * k / runs, n * (k + 1) / runs, sums[k]);
  team.barrier();
  ShapeMatchSums all = sums[0];
  for (std::size_t k = 1; k < runs; ++k) all += sums[k];
  return shapeMatchFrame(all, sm, rotation);
}

}  // namespace

// What the damped sweeps compare with, at the start of the substep: F of every tet (each member a
// share) and the shape-matching frame of the particles then.
void World::recordSubstepStart(const sweeps::LanePlan& plan, const SolverTeam& team) {
  for (Body& b : bodies_) {
    if (b.state != BodyState::Active) continue;
    const BodyModel& m = *b.model;
    if (m.shapeMatching && m.damping.shapeMatching > 0.0f) {
      Eigen::Quaterniond rotation = b.shapeMatchRotation;
      const ShapeMatchFrame frame = shapeMatchFrameOf(*m.shapeMatching, local_.data() + b.firstParticle,
                                                      shapeMatchSums_, *plan.widths[0], team, rotation);
      team.barrier();  // every member has read the sums
      if (team.leader()) b.shapeMatchStart = frame;
    }
    if (b.startDeformation.empty()) continue;
    const sweeps::Range r{nullptr, local_.data() + b.firstParticle, 0.0f, nullptr};
    const auto [begin, end] = team.share(0, m.strain.size(), 16);
    plan.run(begin, end, [&](const sweeps::LaneSweeps& s, std::size_t first, std::size_t last) {
      s.startDeformation(m.strain.data(), first, last, b.startDeformation.data(), m.strain.size(), r);
    });
  }
  team.barrier();
}

namespace {

// One constraint array in colour order (colours run through the lanes by LanePlan::run, then the
// remainder one at a time), by a team of threads:
//  - an array too small to be cut in groups (body_model.cpp) by the last member alone, the others
//    waiting once: a barrier per colour would cost more than the colour;
//  - one cut in groups for two threads (twoThreadGroups), by a team of two, a pair of groups at a
//    time: one group each, colour after colour, with a barrier only after each pair; a last
//    unpaired group and the remainder by the last member;
//  - otherwise each colour shared by the team, a barrier after each; a run of colours too small
//    to give every member a batch, and the remainder, by the last member, one barrier after each.
// The last member, because the leader has the serial work (attachments, triangle contacts). Only
// constraints that share no particle run at once, so the result is the one-thread result.
// `project(sweeps, begin, end)` calls the array's sweep of that width.
template <typename Project>
void sweepColours(const std::vector<std::uint32_t>& colours, const std::vector<std::uint32_t>& groups,
                  std::size_t count, const sweeps::LanePlan& plan, const SolverTeam& team, Project project) {
  const std::size_t remainder = colours.empty() ? 0 : colours.back();
  if (team.size > 1 && groups.empty()) {
    if (team.last()) {
      for (std::size_t k = 0; k + 1 < colours.size(); ++k) plan.run(colours[k], colours[k + 1], project);
      if (remainder < count) project(sweeps::scalarSweeps(), remainder, count);
    }
    team.barrier();
    return;
  }
  if (team.size == 2) {
    const auto sweepGroup = [&](std::size_t g) {
      for (std::size_t k = groups[g]; k < groups[g + 1]; ++k) plan.run(colours[k], colours[k + 1], project);
    };
    const std::size_t groupCount = groups.size() - 1;
    std::size_t g = 0;
    for (; g + 1 < groupCount; g += 2) {
      sweepGroup(g + std::size_t(team.index));
      team.barrier();
    }
    if (g < groupCount || remainder < count) {
      if (team.last()) {
        if (g < groupCount) sweepGroup(g);
        if (remainder < count) project(sweeps::scalarSweeps(), remainder, count);
      }
      team.barrier();
    }
    return;
  }
  constexpr std::size_t kAlign = 16;  // the widest lanes: every share but the last holds whole batches
  const auto shared = [&](std::size_t k) { return colours[k + 1] - colours[k] >= kAlign * std::size_t(team.size); };
  for (std::size_t k = 0; k + 1 < colours.size();) {
    if (shared(k)) {
      const auto [begin, end] = team.share(colours[k], colours[k + 1], kAlign);
      plan.run(begin, end, project);
      ++k;
    } else {  // colours too small for a batch each (a group's last): the last member's, one barrier
      const std::size_t first = k;
      while (k + 1 < colours.size() && !shared(k)) ++k;
      if (team.last())
        for (std::size_t c = first; c < k; ++c) plan.run(colours[c], colours[c + 1], project);
    }
    team.barrier();
  }
  if (remainder == count) return;  // the last colour's barrier was the last
  if (team.last()) project(sweeps::scalarSweeps(), remainder, count);
  team.barrier();
}

// Shape matching (eqs. 25-28) of one body by a team: every member finds the same frame
// (shapeMatchFrameOf) and moves its part of the particles; with damping, against the frame at the
// start of the substep (Body::shapeMatchStart).
void shapeMatching(Body& b, float tau, const sweeps::Range& r, std::span<ShapeMatchSums> sums,
                   const sweeps::LaneSweeps& lanes, const SolverTeam& team) {
  const ShapeMatchModel& sm = *b.model->shapeMatching;
  Eigen::Quaterniond rotation = b.shapeMatchRotation;
  const ShapeMatchFrame frame = shapeMatchFrameOf(sm, r.pred, sums, lanes, team, rotation);
  const std::size_t runs = sums.size(), n = sm.restOffsets.size();
  const auto [first, last] = shapeMatchRuns(runs, team);
  lanes.shapeMatch(sm.restOffsets.data(), sm.compliance, frame, b.shapeMatchStart, b.shapeMatchLambda.data(), tau, r,
                   n * first / runs, n * last / runs);
  team.barrier();  // every member has read the sums and the last rotation
  if (team.leader()) b.shapeMatchRotation = rotation;
}

}  // namespace

// One sweep of a constraint stage, and with `measure` its corrections: the moves of the particles
// of `body` (every body's for the world constraints), relative to their body's length, added to
// the stage's residual. The leader copies and compares, between barriers.
template <typename Sweep>
void World::measured(Stage stage, const Body* body, bool measure, const SolverTeam& team, Sweep&& sweep) {
  if (!measure) return sweep();
  const auto each = [&](auto&& f) {
    for (const Body& b : bodies_)
      if (b.state == BodyState::Active && (!body || &b == body))
        for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i) f(b, i);
  };
  if (team.leader()) {
    residualStart_.resize(predicted_.size());
    each([&](const Body&, Index i) { residualStart_[i] = predicted_[i].pos; });
  }
  team.barrier();
  sweep();
  team.barrier();
  if (team.leader()) {
    const std::size_t s = std::size_t(stage);
    each([&](const Body& b, Index i) {
      if (predicted_[i].w == 0.0f) return;  // kinematic: never moved by a constraint
      const double move = double((predicted_[i].pos - residualStart_[i]).norm()) / double(b.lengthScale);
      residualSumSq_[s] += move * move;
      residualMax_[s] = std::max(residualMax_[s], move);
      ++residualCount_[s];
    });
  }
  team.barrier();
}

void World::solveIteration(float h, const sweeps::LanePlan& plan, const SolverTeam& team, bool measure) {
  const float invH = 1.0f / h;
  const bool timed = settings_.timeStages && team.leader();
  StageTimes& times = report_.times;
  Point* const pred = predicted_.data();
  const Point* const start = local_.data();

  for (Body& b : bodies_) {
    if (b.state != BodyState::Active) continue;
    const BodyModel& m = *b.model;
    const ConstraintDamping& tau = m.damping;
    const sweeps::Range r{pred + b.firstParticle, start + b.firstParticle, invH,
                          b.startDeformation.empty() ? nullptr : b.startDeformation.data()};
    // One stage of this body's constraints: swept and timed, and measured when asked.
    const auto stage = [&](Stage which, auto&& sweep) {
      measured(which, &b, measure, team, [&] {
        StageTimer t(times, which, timed);
        sweep();
      });
    };
    if (!m.distance.empty()) {
      const bool damped = tau.distance > 0.0f;
      stage(Stage::Distance, [&] {
        sweepColours(m.distanceColours, m.distanceGroups, m.distance.size(), plan, team,
                     [&](const sweeps::LaneSweeps& s, std::size_t begin, std::size_t end) {
                       s.distance(m.distance.data(), begin, end, b.distanceLambda.data(), tau.distance, damped, r);
                     });
      });
    }
    // Strain before volume: S = F^T F cannot tell a tet from its mirror image, so the signed
    // volume constraint gets the last word on orientation.
    if (settings_.fuseStrainVolume && b.tetsPaired) {
      const bool damped = tau.strainStretch > 0.0f || tau.strainShear > 0.0f || tau.volume > 0.0f;
      stage(Stage::StrainVolume, [&] {
        sweepColours(m.tetColours, m.tetGroups, m.strain.size(), plan, team,
                     [&](const sweeps::LaneSweeps& s, std::size_t begin, std::size_t end) {
                       s.strainVolume(m.strain.data(), m.volume.data(), begin, end, b.strainLambda.data(),
                                      b.volumeLambda.data(), m.strain.size(), tau, damped, r);
                     });
      });
    } else {
      if (!m.strain.empty()) {
        const bool damped = tau.strainStretch > 0.0f || tau.strainShear > 0.0f;
        stage(Stage::Strain, [&] {
          sweepColours(m.tetColours, m.tetGroups, m.strain.size(), plan, team,
                       [&](const sweeps::LaneSweeps& s, std::size_t begin, std::size_t end) {
                         s.strain(m.strain.data(), begin, end, b.strainLambda.data(), m.strain.size(), tau, damped, r);
                       });
        });
      }
      if (!m.volume.empty()) {
        const bool damped = tau.volume > 0.0f;
        stage(Stage::Volume, [&] {
          sweepColours(m.tetColours, m.tetGroups, m.volume.size(), plan, team,
                       [&](const sweeps::LaneSweeps& s, std::size_t begin, std::size_t end) {
                         s.volume(m.volume.data(), begin, end, b.volumeLambda.data(), tau.volume, damped, r);
                       });
        });
      }
    }
    if (!m.bend.empty()) {
      const bool damped = tau.bend > 0.0f;
      // In levels (levelOrder), without groups: on a team, one member sweeps them all.
      stage(Stage::Bend, [&] {
        sweepColours(m.bendLevels, {}, m.bend.size(), plan, team,
                     [&](const sweeps::LaneSweeps& s, std::size_t begin, std::size_t end) {
                       s.bend(m.bend.data(), begin, end, b.bendLambda.data(), tau.bend, damped, r);
                     });
      });
    }
    if (m.shapeMatching)
      stage(Stage::ShapeMatching,
            [&] { shapeMatching(b, tau.shapeMatching, r, shapeMatchSums_, *plan.widths[0], team); });
  }
  measured(Stage::Contact, nullptr, measure, team, [&] { solveWorldConstraints(invH, timed, team); });
  team.barrier();
}

namespace {

// The part of a contact list (made in particle order) whose particles are in [first, last).
template <typename Contact>
std::pair<std::size_t, std::size_t> contactsOf(const std::vector<Contact>& contacts, Index first, Index last) {
  const auto below = [](const Contact& c, Index p) { return c.particle < p; };
  return {std::size_t(std::lower_bound(contacts.begin(), contacts.end(), first, below) - contacts.begin()),
          std::size_t(std::lower_bound(contacts.begin(), contacts.end(), last, below) - contacts.begin())};
}

}  // namespace

// After the bodies' own constraints, so that they have the last word (P3). Attachments and
// triangle contacts by the leader. The contacts that move one particle each (colliders, fingertips
// on particles) are shared by the team at a particle boundary: a particle's contacts stay on one
// member in their order, so the result is the one-thread result.
void World::solveWorldConstraints(float invH, bool timed, const SolverTeam& team) {
  StageTimes& times = report_.times;
  Point* const pred = predicted_.data();
  const Point* const start = local_.data();
  if (!attachments_.empty()) {
    if (team.leader()) {
      StageTimer t(times, Stage::Attachment, timed);
      for (std::size_t a = 0; a < attachments_.size(); ++a) {
        const Attachment& at = attachments_[a];
        if (at.particle == kNoParticle) continue;
        Point& q = pred[at.particle];
        const Vec3 target = frameOf(bodies_[particleBody_[at.particle]].origin, at.target);
        const Vec3 dLambda = solveAttachment(q, target, at.axes, attachmentLambda_[a],
                                             XpbdCoefficients::make(at.compliance, at.dampingTime, invH),
                                             q.pos - start[at.particle].pos);
        attachmentLambda_[a] += dLambda;
        q.pos += q.w * dLambda;
      }
    }
    team.barrier();  // an attached particle may touch something too
  }
  // This member's particles: cut where the collider contacts (the many) are cut evenly.
  const auto cut = [&](int k) {
    if (k == team.size) return std::numeric_limits<Index>::max();
    return k == 0 || colliderContacts_.empty()
               ? Index(0)
               : colliderContacts_[colliderContacts_.size() * std::size_t(k) / std::size_t(team.size)].particle;
  };
  const Index firstParticle = cut(team.index), lastParticle = cut(team.index + 1);
  if (!colliderContacts_.empty()) {
    StageTimer t(times, Stage::Contact, timed);
    const auto [begin, end] = contactsOf(colliderContacts_, firstParticle, lastParticle);
    for (std::size_t c = begin; c < end; ++c) {
      const ColliderContact& con = colliderContacts_[c];
      const Collider& collider = frameCollider(particleBody_[con.particle], con.collider);
      Point& q = pred[con.particle];
      const ContactCorrection r = solveColliderContact(
          q, start[con.particle].pos, closestSurface(collider, q.pos), con.particleRadius, collider,
          contactNormalLambda_[c], contactFrictionLambda_[c], XpbdCoefficients::make(collider.compliance, 0.0f, invH));
      contactNormalLambda_[c] += r.dLambdaNormal;
      contactFrictionLambda_[c] += r.dLambdaFriction;
      q.pos += r.dp;
    }
  }
  if (!fingertipContacts_.empty()) {
    StageTimer t(times, Stage::Fingertip, timed);
    const auto [begin, end] = contactsOf(fingertipContacts_, firstParticle, lastParticle);
    for (std::size_t c = begin; c < end; ++c) {
      const FingertipContact& con = fingertipContacts_[c];
      const Fingertip& f = frameFingertip(particleBody_[con.particle], con.fingertip);
      Point& q = pred[con.particle];
      const Correction<Vec3, 1> r = solveFingertipContact(q, f.center, f.radius, fingertipLambda_[c],
                                                          XpbdCoefficients::make(f.compliance, 0.0f, invH));
      fingertipLambda_[c] += r.dLambda;
      q.pos += r.dp[0];
      const Vec3 friction =
          fingertipFriction(q, start[con.particle].pos, f, fingertipLambda_[c], fingertipFrictionLambda_[c]);
      fingertipFrictionLambda_[c] += friction;
      q.pos += q.w * friction;
    }
  }
  if (fingertipTriangleContacts_.empty() && bodyContacts_.empty()) return;
  team.barrier();  // a triangle's corners may be any member's
  if (!team.leader()) return;
  if (!fingertipTriangleContacts_.empty()) {
    StageTimer t(times, Stage::Fingertip, timed);
    for (std::size_t c = 0; c < fingertipTriangleContacts_.size(); ++c) {
      const FingertipTriangleContact& con = fingertipTriangleContacts_[c];
      const Fingertip& f = frameFingertip(particleBody_[con.i[0]], con.fingertip);
      Point &q0 = pred[con.i[0]], &q1 = pred[con.i[1]], &q2 = pred[con.i[2]];
      const TriangleContactCorrection r =
          solveFingertipTriangleContact(q0, q1, q2, f.center, f.radius, fingertipTriangleLambda_[c],
                                        XpbdCoefficients::make(f.compliance, 0.0f, invH));
      fingertipTriangleLambda_[c] += r.dLambda;
      for (int k = 0; k < 3; ++k) fingertipTriangleImpulse_[c][k] += r.dLambda * r.grad[k];
      q0.pos += r.dp[0];
      q1.pos += r.dp[1];
      q2.pos += r.dp[2];
      const TriangleFriction friction =
          fingertipTriangleFriction(q0, q1, q2, start[con.i[0]].pos, start[con.i[1]].pos, start[con.i[2]].pos, f,
                                    fingertipTriangleLambda_[c], fingertipTriangleFrictionLambda_[c]);
      fingertipTriangleFrictionLambda_[c] += friction.dLambda;
      Point* corner[3] = {&q0, &q1, &q2};
      for (int k = 0; k < 3; ++k) {
        fingertipTriangleImpulse_[c][k] += friction.b[k] * friction.dLambda;
        corner[k]->pos += corner[k]->w * friction.b[k] * friction.dLambda;
      }
    }
  }
  if (!bodyContacts_.empty()) {
    StageTimer t(times, Stage::BodyContact, timed);
    solveBodyContacts(invH);
  }
}

// Each member checks its share of every body, then commits it where no member found a non-finite
// position; the leader contains the bodies that have one (a barrier after, since that moves all of
// the body's particles and changes its state, which the next substep's members read).
void World::finalise(float h, const SolverTeam& team) {
  StageTimer timer(report_.times, Stage::Finalise, settings_.timeStages && team.leader());
  enum : std::uint8_t { kNonFinite, kFinite, kInactive };
  const float invH = 1.0f / h;
  const std::size_t bodies = bodies_.size();
  for (BodyId id = 0; id < bodies; ++id) {
    const Body& b = bodies_[id];
    std::uint8_t flag = kInactive;
    if (b.state == BodyState::Active) {
      bool finite = true;
      for (auto [i, end] = particlesOf(b, team); i < end; ++i) finite &= isFinite(predicted_[i].pos);
      flag = finite ? kFinite : kNonFinite;
    }
    memberFinite_[std::size_t(team.index) * bodies + id] = flag;
  }
  team.barrier();
  bool contained = false;
  // From here on the flags, not the state, which the leader may change (every member read the same).
  for (BodyId id = 0; id < bodies; ++id) {
    if (memberFinite_[id] == kInactive) continue;
    bool finite = true;
    for (int k = 0; k < team.size; ++k) finite &= memberFinite_[std::size_t(k) * bodies + id] == kFinite;
    if (!finite) {
      if (team.leader()) containNonFinite(id);
      contained = true;
      continue;
    }
    for (auto [i, end] = particlesOf(bodies_[id], team); i < end; ++i) {  // Algorithm 1, lines 19-20
      particles_.v[i] = (predicted_[i].pos - local_[i].pos) * invH;
      local_[i].pos = predicted_[i].pos;
    }
  }
  if (contained) team.barrier();
}

void World::containNonFinite(BodyId id) {
  Body& b = bodies_[id];
  Index first = b.firstParticle;
  while (isFinite(predicted_[first].pos)) ++first;
  bool lastStateFinite = true;  // the committed positions; velocities are zeroed anyway
  for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i)
    lastStateFinite &= isFinite(local_[i].pos);
  const std::string what =
      fmt::format("body {}: non-finite position of particle {} in step {}", id, first - b.firstParticle, stepCount_);
  if (settings_.onNan == NanPolicy::Freeze && lastStateFinite) {
    for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i) {
      predicted_[i].pos = local_[i].pos;
      particles_.v[i].setZero();
    }
    b.state = BodyState::Frozen;
    events_.push_back({stepCount_, id, what + "; frozen at its last finite state"});
  } else {
    resetBody(id);
    events_.push_back({stepCount_, id, what + "; reset to its initial pose"});
  }
}

// With a world position written since the last step, where ingest will put it.
Vec3 World::framePosition(Index i) const {
  const Vec3d& origin = bodies_[particleBody_[i]].origin;
  const Vec3& x = particles_.x[i].pos;
  return x != worldOf(origin, local_[i].pos) ? frameOf(origin, x) : local_[i].pos;
}

Vec3d World::position(Index particle) const {
  if (particle >= particles_.size()) throw Error(fmt::format("position: no particle {}", particle));
  return bodies_[particleBody_[particle]].origin + framePosition(particle).cast<double>();
}

double World::volume(BodyId id) const {
  const Body& b = bodies_.at(id);
  const auto at = [&](Index v) -> Vec3d { return framePosition(b.firstParticle + v).cast<double>(); };
  double sum = 0.0;
  for (const Tet& t : b.model->tets) sum += signedTetVolume<double>(at(t[0]), at(t[1]), at(t[2]), at(t[3]));
  return sum;
}

std::size_t World::bodyBytes(BodyId id) const {
  const Body& b = bodies_.at(id);
  const auto bytes = [](const auto& v) { return v.capacity() * sizeof(v[0]); };
  const std::size_t perParticle = 3 * sizeof(Point) + 2 * sizeof(Vec3) + sizeof(BodyId);  // x, frame x and p, v, force
  return b.model->bytes() + bytes(b.distanceLambda) + bytes(b.volumeLambda) + b.strainLambda.bytes() +
         bytes(b.bendLambda) + bytes(b.startDeformation) + bytes(b.shapeMatchLambda) + bytes(b.initialPositions) +
         b.particleCount * perParticle;
}

double World::volumeLoss(BodyId id) const {
  const double v0 = bodies_.at(id).model->restVolume;
  return v0 > 0.0 ? (v0 - volume(id)) / v0 : 0.0;
}

namespace {

// Each of a body's constraints with its multiplier (the tets' only with `tets`): add(particles,
// grad C at positions x, lambda). The generalised forces are lambda grad C / h^2; the shape
// match's multipliers are its moves.
template <typename Add>
void forEachMultiplier(const Body& b, const Point* x, bool tets, Add&& add) {
  const BodyModel& m = *b.model;
  for (std::size_t c = 0; c < m.distance.size(); ++c) {
    const auto& con = m.distance[c];
    const Vec3 n = evalDistance(x[con.i[0]].pos, x[con.i[1]].pos, con.restLength).n;
    add(con.i, std::array<Vec3, 2>{n, -n}, b.distanceLambda[c]);
  }
  for (std::size_t c = 0; tets && c < m.volume.size(); ++c) {
    const auto& con = m.volume[c];
    add(con.i, evalVolume(x[con.i[0]].pos, x[con.i[1]].pos, x[con.i[2]].pos, x[con.i[3]].pos, con.restVolume).grad,
        b.volumeLambda[c]);
  }
  for (std::size_t c = 0; tets && c < m.strain.size(); ++c) {
    const auto& con = m.strain[c];
    for (int k = 0; k < kStrainComponents; ++k)
      add(con.i,
          evalStrainComponent(x[con.i[0]].pos, x[con.i[1]].pos, x[con.i[2]].pos, x[con.i[3]].pos, con.invRestShape, k)
              .grad,
          b.strainLambda[c][k]);
  }
  for (std::size_t c = 0; c < m.bend.size(); ++c) {
    const auto& con = m.bend[c];
    add(con.i, evalBend(x[con.i[0]].pos, x[con.i[1]].pos, x[con.i[2]].pos, x[con.i[3]].pos, con.restAngle).grad,
        b.bendLambda[c]);
  }
}

}  // namespace

std::vector<Vec3> World::particleMaterialForces(BodyId id) const {
  const Body& b = bodies_.at(id);
  const float h = substepSize(), invH2 = 1.0f / (h * h);
  std::vector<Vec3> f(b.particleCount, Vec3::Zero());
  forEachMultiplier(b, local_.data() + b.firstParticle, true, [&](const auto& idx, const auto& grad, float lambda) {
    for (std::size_t k = 0; k < std::size(idx); ++k) f[idx[k]] += lambda * invH2 * grad[k];
  });
  for (std::size_t i = 0; i < b.shapeMatchLambda.size(); ++i) f[i] += b.shapeMatchLambda[i] * invH2;
  return f;
}

// The warm start (SolverSettings::warmStart): each prediction p~ moves by w grad C(p~)^T lambda of
// the last substep's multipliers, so that the multipliers and the positions start consistent
// (M (p - p~) = grad C^T lambda), as XPBD's update assumes. The tets in lanes, colour by colour,
// by the team; the rest by the leader.
void World::warmStart(const sweeps::LanePlan& plan, const SolverTeam& team) {
  for (Body& b : bodies_) {
    if (b.state != BodyState::Active) continue;
    const BodyModel& m = *b.model;
    const sweeps::Range r{predicted_.data() + b.firstParticle, inertial_.data() + b.firstParticle, 0.0f, nullptr};
    if (!m.strain.empty())
      sweepColours(m.tetColours, m.tetGroups, m.strain.size(), plan, team,
                   [&](const sweeps::LaneSweeps& s, std::size_t begin, std::size_t end) {
                     s.warmStrain(m.strain.data(), begin, end, b.strainLambda.data(), m.strain.size(), r);
                   });
    if (!m.volume.empty())
      sweepColours(m.tetColours, m.tetGroups, m.volume.size(), plan, team,
                   [&](const sweeps::LaneSweeps& s, std::size_t begin, std::size_t end) {
                     s.warmVolume(m.volume.data(), begin, end, b.volumeLambda.data(), r);
                   });
    if (!team.leader()) continue;
    Point* const p = r.pred;
    forEachMultiplier(b, r.start, false, [&](const auto& idx, const auto& grad, float lambda) {
      for (std::size_t k = 0; k < std::size(idx); ++k) p[idx[k]].pos += p[idx[k]].w * lambda * grad[k];
    });
    for (std::size_t i = 0; i < b.shapeMatchLambda.size(); ++i) p[i].pos += p[i].w * b.shapeMatchLambda[i];
  }
  team.barrier();
}

std::vector<Vec3> World::particleConstraintForces(BodyId id) const {
  const Body& b = bodies_.at(id);
  const float h = substepSize(), invH2 = 1.0f / (h * h);
  std::vector<Vec3> f = particleMaterialForces(id);
  auto local = [&](Index particle) -> Vec3* {
    return particle >= b.firstParticle && particle < b.firstParticle + b.particleCount ? &f[particle - b.firstParticle]
                                                                                       : nullptr;
  };
  for (std::size_t a = 0; a < attachments_.size(); ++a)
    if (Vec3* fi = attachments_[a].particle == kNoParticle ? nullptr : local(attachments_[a].particle))
      *fi += attachmentLambda_[a] * invH2;
  for (std::size_t c = 0; c < colliderContacts_.size(); ++c)
    if (Vec3* fi = local(colliderContacts_[c].particle)) {
      const Vec3 n =
          closestSurface(frameCollider(id, colliderContacts_[c].collider), local_[colliderContacts_[c].particle].pos)
              .normal;
      *fi += (contactNormalLambda_[c] * n + contactFrictionLambda_[c]) * invH2;
    }
  for (std::size_t c = 0; c < fingertipContacts_.size(); ++c)
    if (Vec3* fi = local(fingertipContacts_[c].particle)) {
      const Fingertip& tip = frameFingertip(id, fingertipContacts_[c].fingertip);
      *fi += (fingertipLambda_[c] *
                  evalSphereContact(local_[fingertipContacts_[c].particle].pos, tip.center, tip.radius).n +
              fingertipFrictionLambda_[c]) *
             invH2;
    }
  for (std::size_t c = 0; c < fingertipTriangleContacts_.size(); ++c)
    for (int k = 0; k < 3; ++k)
      if (Vec3* fi = local(fingertipTriangleContacts_[c].i[k])) *fi += fingertipTriangleImpulse_[c][k] * invH2;
  for (std::size_t c = 0; c < bodyContacts_.size(); ++c) {
    const BodyContact& con = bodyContacts_[c];
    const Vec3 push = (bodyContactLambda_[c] * con.normal + bodyContactFrictionLambda_[c]) * invH2;
    for (std::size_t k = 0; k < 4; ++k)
      if (Vec3* fi = local(con.particle[k])) *fi += con.weight[k] * push;
  }
  return f;
}

}  // namespace vrd
