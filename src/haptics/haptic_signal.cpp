#include "vrdeform/haptics/haptic_signal.h"

#include <algorithm>
#include <cmath>

namespace vrd {

// clampUnit (math/types.h) maps NaN to 0 as well: a broken multiplier must not reach the glove.

float normalisedContact(float lambdaSum, std::size_t contactCount, float tauContact) {
  if (contactCount == 0) return 0.0f;
  return clampUnit(std::abs(lambdaSum) / (float(contactCount) * tauContact));
}

float tetSignal(float volumeLambda, const StrainLambda& strainLambda, const HapticSignalSettings& s) {
  float strainSq = 0.0f;
  for (float l : strainLambda) strainSq += l * l;
  return s.betaVolume * clampUnit(std::abs(volumeLambda) / s.tauVolume) +
         s.betaStrain * clampUnit(std::sqrt(strainSq) / s.tauStrain);
}

float volumeStrainSignal(std::span<const Vec3> centroids, std::span<const float> tetSignals, const Vec3& graspCentre,
                         float epsilon) {
  double weighted = 0.0, weights = 0.0;
  for (std::size_t j = 0; j < centroids.size() && j < tetSignals.size(); ++j) {
    const double w = 1.0 / (double((centroids[j] - graspCentre).norm()) + epsilon);
    weighted += w * tetSignals[j];
    weights += w;
  }
  return weights > 0.0 ? clampUnit(float(weighted / weights)) : 0.0f;
}

float rawHapticForce(bool grasping, std::size_t contactCount, float contactSignal, float volumeStrain,
                     const HapticSignalSettings& s) {
  if (grasping) return clampUnit(volumeStrain);
  if (contactCount > 0) return clampUnit(s.betaContact * contactSignal + (1.0f - s.betaContact) * volumeStrain);
  return 0.0f;
}

float smoothHapticForce(float previous, float raw, float alphaT) {
  return clampUnit((1.0f - alphaT) * clampUnit(previous) + alphaT * clampUnit(raw));
}

float limitChange(float previous, float next, float maxStep) {
  return std::clamp(next, previous - maxStep, previous + maxStep);
}

}  // namespace vrd
