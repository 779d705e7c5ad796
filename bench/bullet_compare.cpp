// vrdeform's XPBD solver side by side with Bullet's classic soft bodies (btSoftBody), in one run,
// on the identical tet grid: a 1 m cube of N^3 cells (6 tets each) resting on the ground, stiff
// (E = 1e7 Pa), dt = 1/60 s, one substep, K iterations, edge + volume constraints.
//
// vrdeform: Material::elastic {E, nu = 0.3, rho}, ConstraintSet::edgesAndVolume(), a ground plane.
// Bullet:   btSoftRigidDynamicsWorld, a node per vertex with its lumped tet mass, a link per unique
//           tet edge (kLST = 1), the tets appended with appendTetra, piterations = K. Bullet's
//           classic position solver has no per-tet volume constraint (its sequence is anchors,
//           rigid contacts, soft contacts, links; tetras only feed the newer deformable solver), so
//           volume is kept the only way it offers: kVC, a pressure force kVC (V0 - V) on the
//           boundary faces, with setPose(volume = true). The ground is a static box (its sparse
//           SDF needs a convex shape; a btStaticPlaneShape is not), collisions SDF_RS.
//
// Reported per engine: wall time per step (mean and min over F frames after 10 warm-up frames);
// at 2 s (or after the timed frames, if later) the worst edge strain max |l / l0 - 1|, the volume
// change and the number of inverted tets (signed volume <= 0); and the sag over the last 0.5 s:
// rest height minus the mean y of the top layer, measured from the mean y of the bottom layer so
// that Bullet's collision margin does not count.
//
// Not a test: built only where Bullet is found (bench/CMakeLists.txt). See docs/performance.md.

#include <btBulletDynamicsCommon.h>
#include <fmt/format.h>

#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "vrdeform/error.h"
#include "vrdeform/mesh/boundary.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

constexpr float kSize = 1.0f;        // cube edge (m)
constexpr float kDensity = 1000.0f;  // kg/m^3
constexpr float kYoung = 1e7f;       // Pa
constexpr float kPoisson = 0.3f;
constexpr float kTimeStep = 1.0f / 60.0f;
constexpr float kGravity = -9.81f;
constexpr int kWarmUp = 10;
constexpr int kSettleFrames = 120;      // the shape is measured after 2 s, or after the timed frames if later
constexpr int kSagFrames = 30;          // the sag is averaged over the last 0.5 s
constexpr float kBulletMargin = 0.01f;  // soft body collision margin (m); Bullet's default is 0.25

struct Options {
  std::vector<int> cells{6, 12, 26};
  int iterations = 5;
  int frames = 0;   // 0: 60, or 30 for grids above 20 cells
  int threads = 0;  // 0: 2 where the machine has 2 cores or more, else 1
  // Bullet integrates the kVC pressure explicitly: the physical K / V0 (8.3e6 for this cube) and
  // 1e6 blow up from 12 cells on, 1e5 stays finite at every size (docs/performance.md).
  double bulletKvc = 1e5;
  bool json = false;
};

/// The mesh both engines get, and what the measurements need from it.
struct Scenario {
  int cells = 0;
  TetMesh mesh;
  std::vector<std::array<Index, 2>> edges;  // unique tet edges
  std::vector<double> restLength;
  std::vector<double> nodeMass;  // lumped: rho V / 4 from each tet
  std::vector<Index> top, bottom;
  double restVolume = 0;
};

Scenario makeScenario(int cells) {
  Scenario s;
  s.cells = cells;
  s.mesh = makeBoxTets(Vec3::Zero(), Vec3::Constant(kSize), cells, cells, cells);
  const auto& x = s.mesh.vertices;
  s.nodeMass.assign(x.size(), 0.0);
  for (const Tet& t : s.mesh.tets) {
    const double v = signedTetVolume<double>(x[t[0]].cast<double>(), x[t[1]].cast<double>(), x[t[2]].cast<double>(),
                                             x[t[3]].cast<double>());
    s.restVolume += v;
    for (Index i : t) s.nodeMass[i] += kDensity * v / 4.0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) s.edges.push_back({std::min(t[a], t[b]), std::max(t[a], t[b])});
  }
  std::sort(s.edges.begin(), s.edges.end());
  s.edges.erase(std::unique(s.edges.begin(), s.edges.end()), s.edges.end());
  for (const auto& e : s.edges) s.restLength.push_back(double((x[e[0]] - x[e[1]]).norm()));
  const float half = 0.5f * kSize / float(cells);
  for (Index i = 0; i < x.size(); ++i) {
    if (x[i].y() > kSize - half) s.top.push_back(i);
    if (x[i].y() < half) s.bottom.push_back(i);
  }
  return s;
}

struct Outcome {
  double meanMs = 0, minMs = 0;
  double sagMm = 0;         // rest height - (mean top y - mean bottom y)
  double edgeStrain = 0;    // max |l / l0 - 1|
  double volumeChange = 0;  // (V - V0) / V0
  std::size_t inverted = 0;
  bool finite = true;
};

double sagMm(const Scenario& s, const std::vector<Vec3d>& x) {
  auto meanY = [&](const std::vector<Index>& nodes) {
    double sum = 0;
    for (Index i : nodes) sum += x[i].y();
    return sum / double(nodes.size());
  };
  return 1e3 * (double(kSize) - (meanY(s.top) - meanY(s.bottom)));
}

/// Fills the end-of-run shape measurements of `out` from the final positions.
void measureShape(const Scenario& s, const std::vector<Vec3d>& x, Outcome& out) {
  out.finite = std::all_of(x.begin(), x.end(), [](const Vec3d& p) { return p.allFinite(); });
  out.edgeStrain = 0;
  for (std::size_t e = 0; e < s.edges.size(); ++e) {
    const double l = (x[s.edges[e][0]] - x[s.edges[e][1]]).norm();
    out.edgeStrain = std::max(out.edgeStrain, std::abs(l / s.restLength[e] - 1.0));
  }
  double volume = 0;
  out.inverted = 0;
  for (const Tet& t : s.mesh.tets) {
    const double v = signedTetVolume(x[t[0]], x[t[1]], x[t[2]], x[t[3]]);
    volume += v;
    if (!(v > 0)) ++out.inverted;
  }
  out.volumeChange = (volume - s.restVolume) / s.restVolume;
}

/// Runs one engine: `frames` timed steps after the warm-up, then untimed ones up to kSettleFrames;
/// the sag is averaged over the last kSagFrames (an undamped stiff body still rings), the rest is
/// measured after the last step. `positions` writes the engine's current node positions.
template <typename Step, typename Positions>
Outcome simulate(const Scenario& s, int frames, Step&& step, Positions&& positions) {
  Outcome out;
  const int total = std::max(kWarmUp + frames, kSettleFrames);
  double sum = 0, best = std::numeric_limits<double>::infinity(), sag = 0;
  std::vector<Vec3d> x(s.mesh.vertices.size());
  for (int f = 0; f < total; ++f) {
    const auto t0 = std::chrono::steady_clock::now();
    step();
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (f >= kWarmUp && f < kWarmUp + frames) {
      sum += ms;
      best = std::min(best, ms);
    }
    if (f >= total - kSagFrames) {
      positions(x);
      sag += sagMm(s, x);
    }
  }
  out.meanMs = sum / frames;
  out.minMs = best;
  out.sagMm = sag / kSagFrames;
  measureShape(s, x, out);
  return out;
}

Outcome runVrdeform(const Scenario& s, const Options& opt, int threads) {
  SolverSettings settings;
  settings.timeStep = kTimeStep;
  settings.substeps = 1;
  settings.iterations = opt.iterations;
  settings.gravity = Vec3(0, kGravity, 0);
  settings.threads = threads;
  settings.timeStages = false;
  Material material;
  material.elastic = ElasticModuli{kYoung, kPoisson, kDensity, 0.0f};
  World world(settings);
  const BodyId body = world.addBody(makeSoftBody(s.mesh, material, ConstraintSet::edgesAndVolume()));
  world.addCollider(Collider::plane(Vec3::UnitY()));
  return simulate(
      s, opt.frames, [&] { world.step(); },
      [&](std::vector<Vec3d>& x) {
        for (std::size_t i = 0; i < x.size(); ++i)
          x[i] = world.particles().x[world.particleIndex(body, Index(i))].pos.cast<double>();
      });
}

/// A Bullet soft-rigid world holding the cube and the ground; members in construction order.
struct BulletScene {
  btSoftBodyRigidBodyCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btSoftRigidDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  btBoxShape groundShape{btVector3(5, 0.5, 5)};
  std::unique_ptr<btRigidBody> ground;
  std::unique_ptr<btSoftBody> cube;

  BulletScene(const Scenario& s, int iterations, double kvc) {
    const btVector3 g(0, kGravity, 0);
    world.setGravity(g);
    btSoftBodyWorldInfo& info = world.getWorldInfo();
    info.m_gravity = g;
    info.m_sparsesdf.Initialize();

    btTransform groundPose;
    groundPose.setIdentity();
    groundPose.setOrigin(btVector3(0, -0.5, 0));  // top face at y = 0
    ground = std::make_unique<btRigidBody>(0.0, nullptr, &groundShape);
    ground->setWorldTransform(groundPose);
    world.addRigidBody(ground.get());

    // This constructor (unlike the one taking only the world info) also creates the default material.
    std::vector<btVector3> x;
    std::vector<btScalar> mass;
    for (std::size_t i = 0; i < s.mesh.vertices.size(); ++i) {
      const Vec3& p = s.mesh.vertices[i];
      x.emplace_back(p.x(), p.y(), p.z());
      mass.push_back(btScalar(s.nodeMass[i]));
    }
    cube = std::make_unique<btSoftBody>(&info, int(x.size()), x.data(), mass.data());
    btSoftBody::Material* material = cube->m_materials[0];
    material->m_kLST = 1;  // links as stiff as Bullet makes them
    material->m_kAST = 1;
    material->m_kVST = 1;
    for (const auto& e : s.edges) cube->appendLink(int(e[0]), int(e[1]), material, false);
    for (const Tet& t : s.mesh.tets) cube->appendTetra(int(t[0]), int(t[1]), int(t[2]), int(t[3]), material);
    // Faces give kVC the surface its pressure acts on (and the volume it measures).
    for (const Triangle& f : boundaryFaces(s.mesh)) cube->appendFace(int(f[0]), int(f[1]), int(f[2]), material);

    btSoftBody::Config& cfg = cube->m_cfg;
    cfg.piterations = iterations;
    cfg.viterations = 0;
    cfg.diterations = 0;
    cfg.kDP = 0;  // no damping, as on the vrdeform side
    cfg.kVC = btScalar(kvc);
    cfg.collisions = btSoftBody::fCollision::SDF_RS;
    cube->setPose(kvc > 0, false);  // records the rest volume V0 for kVC
    cube->getCollisionShape()->setMargin(kBulletMargin);
    world.addSoftBody(cube.get());
  }
  ~BulletScene() {
    world.removeSoftBody(cube.get());
    world.removeRigidBody(ground.get());
  }
  BulletScene(const BulletScene&) = delete;
  BulletScene& operator=(const BulletScene&) = delete;
};

Outcome runBullet(const Scenario& s, const Options& opt) {
  BulletScene scene(s, opt.iterations, opt.bulletKvc);
  // maxSubSteps = 0: exactly one internal step of dt per call.
  return simulate(
      s, opt.frames, [&] { scene.world.stepSimulation(kTimeStep, 0); },
      [&](std::vector<Vec3d>& x) {
        for (std::size_t i = 0; i < x.size(); ++i) {
          const btVector3& p = scene.cube->m_nodes[int(i)].m_x;
          x[i] = Vec3d(p.x(), p.y(), p.z());
        }
      });
}

struct Row {
  int cells;
  std::size_t tets, edges;
  int frames;
  Outcome vrd1;
  std::optional<Outcome> vrdN;
  Outcome bullet;
};

std::string num(double v, int decimals) { return std::isfinite(v) ? fmt::format("{:.{}f}", v, decimals) : "nan"; }

void printTable(const std::vector<Row>& rows, const Options& opt) {
  const unsigned cores = std::thread::hardware_concurrency();
  fmt::print(
      "vrdeform vs Bullet {}.{:02} soft bodies: 1 m cube on the ground, rho {} kg/m^3, E {:g} Pa (vrdeform), "
      "dt 1/60 s, 1 substep, {} iterations, edges + volume\n",
      BT_BULLET_VERSION / 100, BT_BULLET_VERSION % 100, kDensity, kYoung, opt.iterations);
  fmt::print(
      "machine: {} cores (nproc); Bullet single-threaded, kLST 1, kVC {:g}, SDF_RS\n"
      "times per step: mean (min) over the timed frames after {} warm-up frames; strain, volume change (dV) and "
      "inverted tets at {:g} s, sag averaged over the last {:g} s\n",
      cores, opt.bulletKvc, kWarmUp, kSettleFrames * kTimeStep, kSagFrames * kTimeStep);
  const std::string vrdN = opt.threads > 1 ? fmt::format("vrd {} thr (ms)", opt.threads) : "";
  fmt::print(
      "{:>5} {:>7} {:>6} | {:>17} {:>17} | {:>17} | {:>8} {:>8} | {:>8} {:>8} | {:>8} {:>8} | {:>6} {:>6} | "
      "{:>6} {:>6}\n",
      "cells", "tets", "frames", "vrd 1 thr (ms)", vrdN, "Bullet (ms)", "Bt/vrd1", opt.threads > 1 ? "Bt/vrdN" : "",
      "sag vrd", "Bullet", "strain", "Bullet", "dV vrd", "Bullet", "inv", "Bullet");
  fmt::print(
      "{:>5} {:>7} {:>6} | {:>17} {:>17} | {:>17} | {:>8} {:>8} | {:>8} {:>8} | {:>8} {:>8} | {:>6} {:>6} | "
      "{:>6} {:>6}\n",
      "", "", "", "mean (min)", "", "mean (min)", "", "", "(mm)", "(mm)", "vrd", "", "(%)", "(%)", "vrd", "");
  auto time = [](const Outcome& o) { return fmt::format("{} ({})", num(o.meanMs, 2), num(o.minMs, 2)); };
  for (const Row& r : rows) {
    fmt::print(
        "{:>5} {:>7} {:>6} | {:>17} {:>17} | {:>17} | {:>8} {:>8} | {:>8} {:>8} | {:>8} {:>8} | {:>6} {:>6} | "
        "{:>6} {:>6}\n",
        r.cells, r.tets, r.frames, time(r.vrd1), r.vrdN ? time(*r.vrdN) : "", time(r.bullet),
        num(r.bullet.meanMs / r.vrd1.meanMs, 2), r.vrdN ? num(r.bullet.meanMs / r.vrdN->meanMs, 2) : "",
        num(r.vrd1.sagMm, 2), num(r.bullet.sagMm, 2), num(r.vrd1.edgeStrain, 4), num(r.bullet.edgeStrain, 4),
        num(100 * r.vrd1.volumeChange, 2), num(100 * r.bullet.volumeChange, 2), r.vrd1.inverted, r.bullet.inverted);
  }
}

std::string jsonNum(double v) { return std::isfinite(v) ? fmt::format("{:.6g}", v) : "null"; }

std::string jsonOutcome(const Outcome& o) {
  return fmt::format(
      R"({{"mean_ms": {}, "min_ms": {}, "sag_mm": {}, "max_edge_strain": {}, "volume_change": {}, "inverted_tets": {}, "finite": {}}})",
      jsonNum(o.meanMs), jsonNum(o.minMs), jsonNum(o.sagMm), jsonNum(o.edgeStrain), jsonNum(o.volumeChange), o.inverted,
      o.finite);
}

void printJson(const std::vector<Row>& rows, const Options& opt) {
  fmt::print(R"({{"cores": {}, "iterations": {}, "time_step": {}, "youngs_modulus": {}, "density": {}, )"
             R"("bullet_version": {}, "bullet_kvc": {}, "threads": {}, "rows": [)",
             std::thread::hardware_concurrency(), opt.iterations, jsonNum(kTimeStep), jsonNum(kYoung),
             jsonNum(kDensity), BT_BULLET_VERSION, jsonNum(opt.bulletKvc), opt.threads);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    fmt::print(R"({}{{"cells": {}, "tets": {}, "edges": {}, "frames": {}, "vrdeform_1_thread": {}, )", i ? ", " : "",
               r.cells, r.tets, r.edges, r.frames, jsonOutcome(r.vrd1));
    if (r.vrdN) fmt::print(R"("vrdeform_{}_threads": {}, )", opt.threads, jsonOutcome(*r.vrdN));
    fmt::print(R"("bullet": {}}})", jsonOutcome(r.bullet));
  }
  fmt::print("]}}\n");
}

int run(Options opt) {
  if (opt.threads == 0) opt.threads = std::thread::hardware_concurrency() >= 2 ? 2 : 1;
  std::vector<Row> rows;
  for (int cells : opt.cells) {
    const Scenario s = makeScenario(cells);
    Options o = opt;
    if (o.frames == 0) o.frames = cells > 20 ? 30 : 60;
    Row r{cells, s.mesh.tets.size(), s.edges.size(), o.frames, {}, {}, {}};
    r.vrd1 = runVrdeform(s, o, 1);
    if (o.threads > 1) r.vrdN = runVrdeform(s, o, o.threads);
    r.bullet = runBullet(s, o);
    rows.push_back(r);
  }
  if (opt.json)
    printJson(rows, opt);
  else
    printTable(rows, opt);
  return 0;
}

}  // namespace
}  // namespace vrd

int main(int argc, char** argv) {
  CLI::App app{"vrdeform's XPBD solver against Bullet's classic soft bodies on the same tet grid (not a test)"};
  vrd::Options opt;
  std::vector<int> cells;
  app.add_option("--cells", cells, "cells per side of the cube grid (6 tets each); default 6 12 26")
      ->check(CLI::Range(1, 40));
  app.add_option("--iterations", opt.iterations, "solver iterations per step, both engines")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  app.add_option("--frames", opt.frames, "timed frames after 10 warm-up frames; default 60 (30 above 20 cells)")
      ->check(CLI::Range(1, 100000));
  app.add_option("--threads", opt.threads, "vrdeform threads for the second column; default 2 on 2+ cores")
      ->check(CLI::Range(1, 256));
  app.add_option("--bullet-kvc", opt.bulletKvc, "Bullet's volume conservation coefficient kVC (Pa/m^3), 0 = off")
      ->check(CLI::Range(0.0, 1e12))
      ->capture_default_str();
  app.add_flag("--json", opt.json, "print JSON instead of the table");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (!std::isfinite(opt.bulletKvc)) {  // CLI::Range lets NaN through
    fmt::print(stderr, "--bullet-kvc: must be a finite number >= 0\n");
    return 2;
  }
  if (!cells.empty()) opt.cells = cells;
  try {
    return vrd::run(opt);
  } catch (const vrd::Error& e) {
    fmt::print(stderr, "vrdeform_bullet_compare: {}\n", e.what());
    return 2;
  }
}
