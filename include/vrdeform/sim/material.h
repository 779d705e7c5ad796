#pragma once
// Material settings of a body: per-constraint-type compliance and damping as in the paper, or
// Young's modulus, Poisson ratio and density mapped onto them (docs/materials.md), and the mass
// density its particles' masses are lumped from.

#include <optional>

namespace vrd {

/// Compliance alpha (inverse stiffness, in the constraint's units) and damping beta (eq. 5, in
/// the units of 1/alpha times seconds) of one constraint type. The solver damps with the time
/// tau = alpha * beta (see xpbd.h).
struct ConstraintMaterial {
  float compliance;
  float damping;
};

/// Linear-elastic moduli. When a material has them, the builder derives per-element compliances
/// so that volume + strain constraints reproduce isotropic linear elasticity at small strain, and
/// lumps particle masses from the density.
struct ElasticModuli {
  float youngsModulus;           ///< E (Pa)
  float poissonRatio;            ///< nu, in [0, 0.5)
  float density;                 ///< rho (kg/m^3)
  float rayleighDamping = 0.0f;  ///< stiffness-proportional damping time tau (s); a mode of angular
                                 ///< frequency w gets damping ratio w tau / 2
};

struct Material {
  // Masses are lumped from a density: each tet gives a quarter of rho V to each corner, each cloth
  // triangle a third of rho_A A. The paper's fixed mass per particle only when asked for.
  float density = 1000.0f;            ///< rho (kg/m^3) of a tet mesh without moduli (moduli carry their own)
  float arealDensity = 0.2f;          ///< rho_A (kg/m^2) of a cloth: a light fabric
  std::optional<float> particleMass;  ///< kg per particle instead (the paper: 1 kg); not with moduli

  // The paper's ranges: compliance 0.2-0.4, damping 0.02-0.05.
  ConstraintMaterial distance{0.3f, 0.03f};       ///< stretch (eqs. 7-15); cloth edges and tet edges
  ConstraintMaterial volume{0.3f, 0.03f};         ///< tet volume (eqs. 16-23)
  ConstraintMaterial strainStretch{0.3f, 0.03f};  ///< S_ii - 1 (eq. 33)
  ConstraintMaterial strainShear{0.3f, 0.03f};    ///< S_ij (eq. 34)
  ConstraintMaterial shapeMatching{0.3f, 0.03f};  ///< p_i - g_i (eq. 28), per unit mass
  ConstraintMaterial bending{0.3f, 0.03f};        ///< dihedral angle (eq. 24)

  /// Overrides the density and the distance, volume and strain compliances and damping.
  std::optional<ElasticModuli> elastic;

  float particleRadius = 0.0f;  ///< particles keep this distance from colliders (m); cloth thickness
};

}  // namespace vrd
