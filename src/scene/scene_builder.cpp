#include "vrdeform/scene/scene_builder.h"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>

#include "vrdeform/error.h"
#include "vrdeform/interact/hand_script.h"
#include "vrdeform/io/surface_io.h"
#include "vrdeform/io/tet_io.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;

constexpr double kLargestPlausibleBody = 10.0;  // m across: a larger one gets a warning about units

void say(const SceneLog& log, const std::string& line) {
  if (log) log(line);
}

std::uint64_t fnv1a(std::uint64_t h, const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
  return h;
}

// A fingerprint of a mesh as read, so that a replay notices an edited file.
template <typename Element>
std::uint64_t meshHash(const std::vector<Vec3>& vertices, const std::vector<Element>& elements) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (const Vec3& v : vertices) h = fnv1a(h, v.data(), 3 * sizeof(float));
  for (const Element& e : elements) h = fnv1a(h, e.data(), sizeof(e));
  return h;
}

Mat3 rotationOf(const std::array<float, 3>& degrees) {
  const float k = float(M_PI / 180.0);
  return (Eigen::AngleAxisf(k * degrees[2], Vec3::UnitZ()) * Eigen::AngleAxisf(k * degrees[1], Vec3::UnitY()) *
          Eigen::AngleAxisf(k * degrees[0], Vec3::UnitX()))
      .toRotationMatrix();
}

std::string fileName(const std::string& path) { return fs::path(path).filename().string(); }

Eigen::AlignedBox3f boundsOf(const std::vector<Vec3>& points) {
  Eigen::AlignedBox3f box;
  for (const Vec3& p : points) box.extend(p);
  return box;
}

}  // namespace

PlacedMesh placeBodyMesh(const BodySpec& body, const SceneLog& log, const std::function<bool()>& stop) {
  PlacedMesh out;
  const std::string name = fileName(body.mesh);
  if (body.kind == BodyKind::Cloth) {
    out.surface = readSurface(body.mesh);
    out.hash = meshHash(out.surface.vertices, out.surface.triangles);
    out.tets.vertices = out.surface.vertices;
    say(log, fmt::format("mesh: {} ({} triangles), cloth", name, out.surface.triangles.size()));
  } else if (isSurfaceFile(body.mesh)) {
    TriMesh surface = readSurface(body.mesh);
    out.hash = meshHash(surface.vertices, surface.triangles);
    for (Vec3& v : surface.vertices) v *= body.scale;
    const auto start = std::chrono::steady_clock::now();
    TetrahedraliseOptions mesher = body.mesher;
    mesher.stop = stop;
    if (mesher.mesher == Mesher::TetGen)  // seconds to minutes, where the built-in mesher takes milliseconds
      say(log, fmt::format("mesh: {} ({} triangles): meshing with tetgen (at most {:g} s a run)...", name,
                           surface.triangles.size(), mesher.timeoutSeconds));
    Tetrahedralisation made = tetrahedralise(surface, mesher);
    out.tets = std::move(made.mesh);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    say(log,
        fmt::format("mesh: {} ({} triangles) x {:g}: {} tets from the {} mesher in {:.2f} s", name,
                    surface.triangles.size(), body.scale, out.tets.tets.size(), toString(body.mesher.mesher), seconds));
    if (const std::string dropped = droppedMessage(made); !dropped.empty())
      say(log, fmt::format("note: body '{}': {} (`tets` in the scene file)", body.name, dropped));
  } else {
    out.tets = readTetMesh(body.mesh);
    out.hash = meshHash(out.tets.vertices, out.tets.tets);
    const std::size_t dropped = removeUnusedVertices(out.tets);
    say(log, fmt::format("mesh: {}: {} tets, used as is{}", name, out.tets.tets.size(),
                         dropped > 0 ? fmt::format(" (dropped {} vertices no tet uses)", dropped) : ""));
  }
  if (!body.renderMesh.empty()) {
    out.render = readSurface(body.renderMesh);
    say(log, fmt::format("render mesh: {} ({} vertices, {} triangles)", fileName(body.renderMesh),
                         out.render.vertices.size(), out.render.triangles.size()));
  }
  if (out.tets.vertices.empty()) throw Error(fmt::format("{}: no vertices", body.mesh));

  // Scale (tetrahedralised surfaces were scaled before meshing), rotate, then place.
  const bool scaled = body.kind == BodyKind::Soft && isSurfaceFile(body.mesh);
  const Mat3 rotation = rotationOf(body.rotationDeg);
  const auto transform = [&](std::vector<Vec3>& vertices, bool alreadyScaled) {
    for (Vec3& v : vertices) v = rotation * (alreadyScaled ? v : Vec3(body.scale * v));
  };
  transform(out.tets.vertices, scaled);
  transform(out.surface.vertices, false);
  transform(out.render.vertices, false);
  const Eigen::AlignedBox3f box = boundsOf(out.tets.vertices);
  const Vec3 lo = box.min(), hi = box.max();
  if (!isFinite(lo) || !isFinite(hi)) throw Error(fmt::format("{}: coordinates overflow after scaling", body.mesh));
  // Meshes often come in millimetres, which taken as metres make a body of a giant's size.
  if (const double size = (hi - lo).maxCoeff(); size > kLargestPlausibleBody)
    say(log, fmt::format("warning: body '{}' is {:.3g} m across (the scene's units are metres); if its mesh is in "
                         "millimetres, scale = {:g} makes it {:.3g} m, in centimetres scale = {:g} makes it {:.3g} m",
                         body.name, size, 1e-3 * body.scale, 1e-3 * size, 1e-2 * body.scale, 1e-2 * size));
  const Vec3 shift = body.placement == Placement::Ground
                         ? Vec3(body.position.x() - 0.5f * (lo.x() + hi.x()), body.position.y() - lo.y(),
                                body.position.z() - 0.5f * (lo.z() + hi.z()))
                         : body.position;
  for (std::vector<Vec3>* vs : {&out.tets.vertices, &out.surface.vertices, &out.render.vertices})
    for (Vec3& v : *vs) v += shift;
  return out;
}

namespace {

// Lifts a placed body so that its lowest point sits the two bodies' thicknesses above the highest
// particle of body `b.on` under its footprint (x and z), or above that body's top if none is under it.
void placeOn(PlacedMesh& mesh, const BuiltScene& scene, const BodySpec& b) {
  const SceneBody& below = scene.body(b.on);
  const World& world = *scene.world;
  const Eigen::AlignedBox3f footprint = boundsOf(mesh.tets.vertices);
  float top = -std::numeric_limits<float>::infinity(), under = top;
  const Body& lower = world.body(below.id);
  for (Index i = lower.firstParticle; i < lower.firstParticle + lower.particleCount; ++i) {
    const Vec3& p = world.particles().x[i].pos;
    top = std::max(top, p.y());
    if (p.x() >= footprint.min().x() && p.x() <= footprint.max().x() && p.z() >= footprint.min().z() &&
        p.z() <= footprint.max().z())
      under = std::max(under, p.y());
  }
  const float gap = world.bodyContact(below.id).thickness + b.contact.thickness;
  const float lift = (std::isfinite(under) ? under : top) + gap - footprint.min().y();
  for (std::vector<Vec3>* vs : {&mesh.tets.vertices, &mesh.surface.vertices, &mesh.render.vertices})
    for (Vec3& v : *vs) v.y() += lift;
}

}  // namespace

Eigen::AlignedBox3f bodyBounds(const World& world, BodyId id) {
  const Body& b = world.body(id);
  Eigen::AlignedBox3f box;
  for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i) box.extend(world.particles().x[i].pos);
  return box;
}

Vec3 topPoint(const World& world, BodyId id) {
  const Body& b = world.body(id);
  const auto& x = world.particles().x;
  const Eigen::AlignedBox3f box = bodyBounds(world, id);
  const float nearTop = box.max().y() - 0.01f * box.sizes().y();
  const Vec3 middle = box.center();
  float best = std::numeric_limits<float>::infinity();
  Vec3 top = Vec3::Constant(std::numeric_limits<float>::quiet_NaN());
  for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i) {
    const Vec3& p = x[i].pos;
    const float off = Vec3(p.x() - middle.x(), 0.0f, p.z() - middle.z()).squaredNorm();
    if (p.y() >= nearTop && off < best) best = off, top = p;
  }
  return top;
}

// The highest particle of a body within `reach` of the vertical through `at` (x, z), or `at` when
// there is none: where a fingertip coming down there first meets the body.
Vec3 surfaceBelow(const World& world, BodyId id, const Vec3& at, float reach) {
  const Body& b = world.body(id);
  Vec3 best = at;
  float height = -std::numeric_limits<float>::infinity();
  for (Index i = b.firstParticle; i < b.firstParticle + b.particleCount; ++i) {
    const Vec3& p = world.particles().x[i].pos;
    if (Vec3(p.x() - at.x(), 0.0f, p.z() - at.z()).norm() <= reach && p.y() > height)
      height = p.y(), best = Vec3(at.x(), p.y(), at.z());
  }
  return best;
}

const SceneBody& BuiltScene::body(std::string_view name) const {
  for (const SceneBody& b : bodies)
    if (b.name == name) return b;
  throw Error(fmt::format("scene {}: no body named '{}'", spec.name, name));
}

BuiltScene buildScene(const SceneSpec& spec, const SceneBuildObserver& observer) {
  const SceneLog& log = observer.log;
  const auto stopped = [&] { return observer.stop && observer.stop(); };
  BuiltScene scene;
  scene.spec = spec;
  if (spec.bodies.empty()) throw Error(fmt::format("scene {}: no bodies", spec.name));
  scene.world = std::make_unique<World>(spec.solver);
  World& world = *scene.world;

  for (const BodySpec& b : spec.bodies) {
    SceneBody body;
    body.name = b.name;
    body.kind = b.kind;
    try {
      body.mesh = placeBodyMesh(b, log, observer.stop);
      if (!b.on.empty()) placeOn(body.mesh, scene, b);
      if (b.kind == BodyKind::Cloth) {
        body.model = makeCloth(body.mesh.surface, b.material);
      } else {
        body.model = makeSoftBody(body.mesh.tets, b.material, b.constraints);
        if (!body.mesh.render.vertices.empty()) body.embedding = Embedding::bind(body.mesh.tets, body.mesh.render);
      }
    } catch (const Error& e) {
      throw Error(fmt::format("body '{}': {}", b.name, e.what()));
    } catch (const Stopped& e) {
      throw Stopped(fmt::format("{} body '{}'", e.what(), b.name));
    }
    body.id = world.addBody(body.model);
    world.setBodyContact(body.id, b.contact);
    const Vec3 wind = b.kind == BodyKind::Cloth ? spec.wind : Vec3::Zero();
    if (b.force != Vec3::Zero() || wind != Vec3::Zero()) world.setExternalForce(body.id, b.force, wind);
    if (!b.pin.empty()) {
      const auto& v = body.mesh.tets.vertices;
      const Eigen::AlignedBox3f box = boundsOf(v);
      std::size_t pinned = 0;
      for (Index i = 0; i < v.size(); ++i)
        for (const std::string& side : b.pin) {
          const int axis = side[1] - 'x';
          const float bound = side[0] == '-' ? box.min()[axis] : box.max()[axis];
          if (std::abs(v[i][axis] - bound) <= b.pinTolerance) {
            world.setInverseMass(world.particleIndex(body.id, i), 0.0f);
            ++pinned;
            break;
          }
        }
      if (pinned == 0) throw Error(fmt::format("body '{}': pin {} holds no particle", b.name, b.pin.front()));
      say(log, fmt::format("body '{}': {} particles pinned", b.name, pinned));
    }
    scene.bodies.push_back(std::move(body));
  }
  for (const Collider& c : spec.colliders) world.addCollider(c);
  for (const auto& [a, b] : spec.noContact) world.setPairContact(scene.body(a).id, scene.body(b).id, false);

  const double dt = spec.solver.timeStep;
  const long settleSteps = std::lround(spec.settle / dt), leastSteps = std::lround(0.5 / dt),
             stillSteps = std::max(1L, std::lround(0.2 / dt));
  long steps = 0, still = 0;
  float fastest = 0.0f;
  while (steps < settleSteps) {
    world.step();
    ++steps;
    if (observer.settling) observer.settling(double(steps) * dt, spec.settle);
    if (stopped())
      throw Stopped(fmt::format("stopped while settling, {:.2f} s of {:g} s", double(steps) * dt, spec.settle));
    if (!spec.settleToRest) continue;
    fastest = 0.0f;
    for (std::size_t i = 0; i < world.particles().size(); ++i)
      if (world.particles().x[i].w > 0.0f) fastest = std::max(fastest, world.particles().v[i].norm());
    still = fastest < SceneSpec::kRestSpeed ? still + 1 : 0;
    if (steps >= leastSteps && still >= stillSteps) break;
  }
  scene.settleSeconds = double(steps) * dt;
  scene.settleEvents = world.takeEvents();
  for (const SimEvent& e : scene.settleEvents) say(log, fmt::format("event while settling: {}", e.message));
  for (SceneBody& b : scene.bodies) {
    b.top = topPoint(world, b.id);
    if (!isFinite(b.top)) throw Error(fmt::format("body '{}' did not settle to finite positions", b.name));
  }
  if (!spec.settleToRest)
    say(log, fmt::format("settled for {:g} s", scene.settleSeconds));
  else if (steps < settleSteps)
    say(log, fmt::format("settled for {:.2f} s: at rest", scene.settleSeconds));
  else
    say(log, fmt::format("settled for {:.2f} s: still moving at up to {:.3f} m/s (`settle = SECONDS` in the scene "
                         "file settles as long as it says)",
                         scene.settleSeconds, fastest));

  const HandSpec& hand = spec.hand;
  scene.session.hand = hand.rig;
  scene.session.grasp = hand.grasp;
  scene.session.haptics = spec.haptics.settings;
  if (!hand.enabled) return scene;

  const float radius = hand.rig.geometry.fingertipRadius;
  // Each action aims at its body's top, moved by its offset: where the body settled when planned,
  // and again where the body is when the action starts (a poke may have rolled it away).
  std::vector<std::pair<BodyId, Vec3>> aims;
  for (const ActionSpec& a : hand.actions)
    aims.emplace_back((a.body.empty() ? scene.bodies.front() : scene.body(a.body)).id, a.offset);
  const auto aim = [&world, aims, radius](std::size_t index) {
    const auto [body, offset] = aims[index];
    const Vec3 top = topPoint(world, body);
    if (offset.x() == 0.0f && offset.z() == 0.0f) return top;
    return surfaceBelow(world, body, top + Vec3(offset.x(), 0.0f, offset.z()), 2.0f * radius);
  };
  for (std::size_t i = 0; i < hand.actions.size(); ++i) {
    HandAction action = hand.actions[i].action;
    action.target = aim(i);
    scene.actions.push_back(action);
  }
  if (!hand.script.empty())
    scene.input = std::make_unique<HandScriptInput>(HandScript::load(hand.script));
  else if (!scene.actions.empty())
    scene.input = std::make_unique<HandActionsInput>(scene.actions, radius, aim);

  if (spec.haptics.calibrate) {
    // Calibrate where the first action goes (else on the first body's top), as the hand will touch.
    const SceneBody* body = &scene.bodies.front();
    CalibrationSettings c;
    c.radius = radius;
    c.contact = hand.rig.contact;
    c.friction = hand.rig.friction;
    c.point = body->top;
    c.stop = observer.stop;
    if (!hand.actions.empty()) {
      const ActionSpec& first = hand.actions.front();
      body = first.body.empty() ? body : &scene.body(first.body);
      c.point = scene.actions.front().target;
    }
    try {
      scene.calibration = calibrateHaptics(world, body->id, scene.session.haptics.signal, c);
    } catch (const Error& e) {
      throw Error(fmt::format(
          "calibrating the haptics on body '{}': {} ([haptics] calibrate = false, or touch --no-calibrate, keeps the "
          "default scales)",
          body->name, e.what()));
    }
    scene.session.haptics.signal = scene.calibration->signal;
    say(log, fmt::format("haptics calibrated on '{}': a standard poke {:.1f} mm deep gave {:.4f} N over {} contacts",
                         body->name, 1e3f * scene.calibration->depth, scene.calibration->force,
                         scene.calibration->contacts));
  }
  return scene;
}

}  // namespace vrd
