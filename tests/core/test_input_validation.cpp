// Bad input fails at construction with a message that names the element.

#include <gtest/gtest.h>

#include <limits>

#include "test_support.h"
#include "vrdeform/error.h"
#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/world.h"

namespace vrd {
namespace {

using testing::errorOf;

TetMesh unitTet() { return {{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}, {{0, 1, 2, 3}}}; }

TEST(InputValidation, TetMeshErrorsNameTheElement) {
  TetMesh mesh = makeBoxTets(Vec3::Zero(), Vec3::Ones(), 2, 1, 1);
  const Material m;

  // Messages number tets and vertices from 1, as a user counts them: tets[3] is tet 4.
  TetMesh inverted = mesh;
  std::swap(inverted.tets[3][1], inverted.tets[3][2]);
  std::string msg = errorOf([&] { makeSoftBody(inverted, m); });
  EXPECT_NE(msg.find("tet 4 ("), std::string::npos) << msg;
  EXPECT_NE(msg.find("inverted"), std::string::npos) << msg;

  TetMesh flat = unitTet();
  flat.vertices[3] = Vec3(0.3f, 0.3f, 0.0f);  // in the plane of the other three
  msg = errorOf([&] { makeSoftBody(flat, m); });
  EXPECT_NE(msg.find("tet 1 ("), std::string::npos) << msg;
  EXPECT_NE(msg.find("degenerate"), std::string::npos) << msg;

  TetMesh nan = mesh;
  nan.vertices[5].y() = std::numeric_limits<float>::quiet_NaN();
  msg = errorOf([&] { makeSoftBody(nan, m); });
  EXPECT_NE(msg.find("vertex 6 "), std::string::npos) << msg;

  TetMesh inf = mesh;
  inf.vertices[2].x() = std::numeric_limits<float>::infinity();
  EXPECT_NE(errorOf([&] { makeSoftBody(inf, m); }).find("vertex 3 "), std::string::npos);

  TetMesh outOfRange = mesh;
  outOfRange.tets[7][2] = 999;
  msg = errorOf([&] { makeSoftBody(outOfRange, m); });
  EXPECT_NE(msg.find("tet 8 "), std::string::npos) << msg;
  EXPECT_NE(msg.find("vertex 1000"), std::string::npos) << msg;

  TetMesh repeated = mesh;
  repeated.tets[4][3] = repeated.tets[4][0];
  EXPECT_NE(errorOf([&] { makeSoftBody(repeated, m); }).find("tet 5 "), std::string::npos);

  TetMesh unused = unitTet();
  unused.vertices.push_back(Vec3(5, 5, 5));
  EXPECT_NE(errorOf([&] { makeSoftBody(unused, m); }).find("vertex 5 "), std::string::npos);

  EXPECT_NE(errorOf([&] { makeSoftBody(TetMesh{}, m); }).find("no tetrahedra"), std::string::npos);
}

TEST(InputValidation, MaterialErrors) {
  const TetMesh mesh = unitTet();
  Material m;
  m.particleMass = 0.0f;
  EXPECT_NE(errorOf([&] { makeSoftBody(mesh, m); }).find("mass"), std::string::npos);
  m = Material{};
  m.particleMass = -1.0f;
  EXPECT_NE(errorOf([&] { makeSoftBody(mesh, m); }).find("mass"), std::string::npos);
  m = Material{};
  m.density = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(errorOf([&] { makeSoftBody(mesh, m); }).find("density must be positive"), std::string::npos);
  m = Material{};
  m.arealDensity = 0.0f;
  EXPECT_NE(errorOf([&] { makeSoftBody(mesh, m); }).find("areal density must be positive"), std::string::npos);
  m = Material{};
  m.particleMass = 1.0f;
  m.elastic = ElasticModuli{1e4f, 0.3f, 1000.0f};
  EXPECT_NE(errorOf([&] { makeSoftBody(mesh, m); }).find("cannot go with moduli"), std::string::npos);
  m = Material{};
  m.volume.compliance = -0.1f;
  EXPECT_NE(errorOf([&] { makeSoftBody(mesh, m); }).find("volume compliance"), std::string::npos);
  m = Material{};
  m.strainShear.damping = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(errorOf([&] { makeSoftBody(mesh, m); }).find("strainShear damping"), std::string::npos);
  m = Material{};
  m.elastic = ElasticModuli{1e4f, 0.5f, 1000.0f};
  EXPECT_NE(errorOf([&] { makeSoftBody(mesh, m); }).find("Poisson"), std::string::npos);
  m.elastic = ElasticModuli{-1.0f, 0.3f, 1000.0f};
  EXPECT_NE(errorOf([&] { makeSoftBody(mesh, m); }).find("Young"), std::string::npos);
  m.elastic = ElasticModuli{1e4f, 0.3f, 0.0f};
  EXPECT_NE(errorOf([&] { makeSoftBody(mesh, m); }).find("density"), std::string::npos);
  m.elastic = ElasticModuli{1e4f, 0.3f, 1000.0f};
  EXPECT_NE(
      errorOf([&] { makeCloth(makeGridCloth(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), 2, 2), m); }).find("cloth"),
      std::string::npos);
}

TEST(InputValidation, HandBuiltModelErrorsNameTheItem) {
  BodyModel model;
  model.restPositions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)};
  model.invMass = {1.0f, 1.0f, 1.0f};
  addDistanceConstraint(model, 0, 1, 0.0f);
  model.distance.push_back({{1, 7}, 1.0f, 0.0f});
  World w;
  std::string msg = errorOf([&] { w.addBody(std::make_shared<BodyModel>(model)); });
  EXPECT_NE(msg.find("distance constraint 1"), std::string::npos) << msg;
  EXPECT_NE(msg.find("particle 7"), std::string::npos) << msg;

  model.distance.pop_back();
  model.invMass[2] = -2.0f;
  msg = errorOf([&] { w.addBody(std::make_shared<BodyModel>(model)); });
  EXPECT_NE(msg.find("particle 2"), std::string::npos) << msg;

  model.invMass[2] = 1.0f;
  model.restPositions[1].z() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(errorOf([&] { w.addBody(std::make_shared<BodyModel>(model)); }).find("particle 1"), std::string::npos);
  EXPECT_EQ(w.bodyCount(), 0u);  // nothing half-added
  EXPECT_EQ(w.particles().size(), 0u);
}

TEST(InputValidation, SettingsAndApiArguments) {
  SolverSettings s;
  s.timeStep = 0.0;
  EXPECT_NE(errorOf([&] { World w(s); }).find("time step"), std::string::npos);
  s = SolverSettings{};
  s.timeStep = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(errorOf([&] { World w(s); }).find("time step"), std::string::npos);
  s = SolverSettings{};
  s.substeps = 0;
  EXPECT_NE(errorOf([&] { World w(s); }).find("substeps"), std::string::npos);
  s = SolverSettings{};
  s.iterations = -3;
  EXPECT_NE(errorOf([&] { World w(s); }).find("iterations"), std::string::npos);

  World w;
  w.addBody(makeSoftBody(unitTet(), Material{}));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(errorOf([&] { w.attach(0, Vec3(nan, 0, 0)); }).find("non-finite"), std::string::npos);
  EXPECT_NE(errorOf([&] { w.attach(99, Vec3::Zero()); }).find("particle 99"), std::string::npos);
  EXPECT_NE(errorOf([&] { w.addFingertip(Vec3::Zero(), -1.0f); }).find("radius"), std::string::npos);
  const FingertipId tip = w.addFingertip(Vec3::Zero(), 0.01f);
  EXPECT_NE(errorOf([&] { w.moveFingertip(tip, Vec3(0, nan, 0)); }).find("non-finite"), std::string::npos);
  EXPECT_NE(errorOf([&] { w.setInverseMass(0, -1.0f); }).find("inverse mass"), std::string::npos);
  EXPECT_NE(errorOf([&] { w.addCollider(Collider::sphere(Vec3::Zero(), 0.0f)); }).find("radius"), std::string::npos);
  Collider box = Collider::box(Vec3::Zero(), Vec3::Ones(), 2.0f * Mat3::Identity());
  EXPECT_NE(errorOf([&] { w.addCollider(box); }).find("rotation"), std::string::npos);
  EXPECT_EQ(w.colliders().size(), 0u);
}

}  // namespace
}  // namespace vrd
