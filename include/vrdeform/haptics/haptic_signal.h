#pragma once
// The paper's haptic signal (section 5.2, eqs. 40-44, Algorithm 2 lines 24-41): the solver's
// contact, volume and strain multipliers, normalised, weighted towards the grasp centre, mixed and
// smoothed into one actuator value in [0, 1]. Pure functions over plain arrays; wiring them to a
// World and a glove is the hand-interaction layer's job.

#include <span>
#include <vector>

#include "vrdeform/math/types.h"
#include "vrdeform/sim/strain_constraint.h"

namespace vrd {

/// Algorithm 2's parameters. The tau are the multiplier magnitudes that map to full force; they
/// depend on the material and the time step, so they have no universal default.
struct HapticSignalSettings {
  float tauContact = 1.0f;  ///< tau^C (eq. 40): mean contact multiplier at full force
  /// Beyond the paper: the summed contact multipliers of one fingertip at full force. A finger's
  /// own contact term is sum_i |lambda_i^C| / tauFingerContact, which, unlike eq. 40's mean, does
  /// not drop when one more particle joins the contact set.
  float tauFingerContact = 1.0f;
  float tauVolume = 1.0f;    ///< tau^V (eq. 41)
  float tauStrain = 1.0f;    ///< tau^S (eq. 41)
  float betaContact = 0.5f;  ///< beta_c (eq. 43)
  float betaVolume = 0.5f;   ///< beta_v (eq. 42); beta_v + beta_s = 1
  float betaStrain = 0.5f;   ///< beta_s (eq. 42)
  float epsilon = 1e-3f;     ///< in w_j = 1 / (d_j + epsilon), metres (eq. 42)
  /// Smoothing factor per update (eq. 44): the force trails the multipliers by (1 - alpha_t) /
  /// alpha_t steps, 4 at the paper's 0.2. With a clean source (fingertip friction, smooth pokes)
  /// little smoothing is needed, and 0.7 keeps the lag from depth to force within a step.
  float alphaT = 0.7f;
};

/// Eq. 40 with Algorithm 2's clip (line 36): sum_i |lambda_i^C| over |N(r)| tau^C. 0 for an
/// empty contact set.
float normalisedContact(float lambdaSum, std::size_t contactCount, float tauContact);

/// Eqs. 41-42 for one tet: beta_v clip(|lambda^V| / tau^V) + beta_s clip(||lambda^S|| / tau^S).
float tetSignal(float volumeLambda, const StrainLambda& strainLambda, const HapticSignalSettings& s);

/// tetSignal() of tets [0, out.size()) of one body, the same values: `volume` holds one multiplier
/// per tet or none (no volume constraints), `strain` likewise (StrainLambdas' layout, component k
/// of tet j at k * tets + j), four tets at a time.
void tetSignals(std::span<const float> volume, std::span<const float> strain, const HapticSignalSettings& s,
                std::span<float> out);

/// The tets' centroids c_j and signals f_j, one array per coordinate so that F_VS runs over four
/// tets at a time.
struct TetSignals {
  std::vector<float> x, y, z;  ///< c_j
  std::vector<float> f;        ///< f_j (tetSignal)

  std::size_t size() const { return f.size(); }
  void resize(std::size_t n) { x.resize(n), y.resize(n), z.resize(n), f.resize(n); }
  void setCentroid(std::size_t j, const Vec3& c) { x[j] = c.x(), y[j] = c.y(), z[j] = c.z(); }
};

/// F_VS (eq. 43's inverse-distance average): sum_j w_j f_j / sum_j w_j with w_j = 1 / (d_j +
/// epsilon), d_j the distance from tet j's centroid to the grasp centre. 0 without tets.
float volumeStrainSignal(const TetSignals& tets, const Vec3& graspCentre, float epsilon);

/// Eq. 43: F_VS when grasping; clip(beta_c lambda^C + (1 - beta_c) F_VS) when some particle is in
/// contact; 0 otherwise.
float rawHapticForce(bool grasping, std::size_t contactCount, float contactSignal, float volumeStrain,
                     const HapticSignalSettings& s);

/// Eq. 44: (1 - alpha_t) F_out + alpha_t F_raw. A non-finite F_raw counts as 0, so the actuator
/// never receives NaN; the result stays in [0, 1].
float smoothHapticForce(float previous, float raw, float alphaT);

/// Moves from `previous` towards `next` by at most `maxStep` (beyond the paper: a limit on how
/// fast the actuator may be driven).
float limitChange(float previous, float next, float maxStep);

}  // namespace vrd
