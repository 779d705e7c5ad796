// Particle masses: lumped from the density of a tet mesh or the areal density of a cloth, or the
// paper's fixed mass per particle when a material asks for it.

#include <gtest/gtest.h>

#include <numeric>

#include "vrdeform/mesh/primitives.h"
#include "vrdeform/sim/body_model.h"

namespace vrd {
namespace {

std::vector<double> massesOf(const BodyModel& m) {
  std::vector<double> mass;
  for (float w : m.invMass) mass.push_back(1.0 / double(w));
  return mass;
}

double total(const std::vector<double>& masses) { return std::accumulate(masses.begin(), masses.end(), 0.0); }

TEST(Masses, ATetMeshWeighsItsDensityTimesItsVolume) {
  // A 0.2 x 0.1 x 0.05 m block of 800 kg/m^3: 0.8 kg, whatever its tets.
  const TetMesh mesh = makeBoxTets(Vec3::Zero(), Vec3(0.2f, 0.1f, 0.05f), 4, 3, 2);
  Material m;
  m.density = 800.0f;
  const std::vector<double> mass = massesOf(*makeSoftBody(mesh, m));
  EXPECT_NEAR(total(mass), 800.0 * 0.2 * 0.1 * 0.05, 1e-6 * 0.8);
  // Lumped, not even: a corner (in the fewest tets) is lighter than the mean.
  EXPECT_LT(mass[0], total(mass) / double(mass.size()));

  // Moduli bring their own density, the same way.
  m.elastic = ElasticModuli{1e4f, 0.3f, 1000.0f};
  EXPECT_NEAR(total(massesOf(*makeSoftBody(mesh, m))), 1.0, 1e-6);
}

TEST(Masses, AClothWeighsItsArealDensityTimesItsArea) {
  // A 1.25 m square flag of 0.2 kg/m^2: 0.3125 kg; an interior vertex of the grid carries six
  // triangles' thirds (the area of one cell, 1.25^2 / 100 m^2), a corner one or two.
  const TriMesh mesh = makeGridCloth(Vec3::Zero(), Vec3(1.25f, 0, 0), Vec3(0, 0, 1.25f), 10, 10);
  Material m;
  m.arealDensity = 0.2f;
  const std::vector<double> mass = massesOf(*makeCloth(mesh, m));
  EXPECT_NEAR(total(mass), 0.3125, 1e-6);
  const double cell = 0.2 * 1.25 * 1.25 / 100.0;
  EXPECT_NEAR(*std::max_element(mass.begin(), mass.end()), cell, 1e-6 * cell);
  EXPECT_LT(*std::min_element(mass.begin(), mass.end()), 0.7 * cell);
}

TEST(Masses, AParticleMassGivesEveryParticleTheSame) {
  Material m;
  m.particleMass = 1.0f;  // the paper's
  for (const auto& model : {makeSoftBody(makeBoxTets(Vec3::Zero(), Vec3::Ones(), 2, 2, 2), m),
                            makeCloth(makeGridCloth(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), 3, 3), m)})
    for (float w : model->invMass) EXPECT_EQ(w, 1.0f);
}

}  // namespace
}  // namespace vrd
