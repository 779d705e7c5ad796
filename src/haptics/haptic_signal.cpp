#include "vrdeform/haptics/haptic_signal.h"

#include <algorithm>
#include <cmath>

namespace vrd {
namespace {

// clip(x, 0, 1) that also maps NaN to 0: a broken multiplier must not reach the glove.
float unitClip(float x) { return x > 0.0f ? std::min(x, 1.0f) : 0.0f; }

}  // namespace

float normalisedContact(std::span<const float> contactLambda, float tauContact) {
  if (contactLambda.empty()) return 0.0f;
  double sum = 0.0;
  for (float l : contactLambda) sum += std::abs(l);
  return unitClip(float(sum / (double(contactLambda.size()) * tauContact)));
}

float tetSignal(float volumeLambda, const StrainLambda& strainLambda, const HapticSignalSettings& s) {
  float strainSq = 0.0f;
  for (float l : strainLambda) strainSq += l * l;
  return s.betaVolume * unitClip(std::abs(volumeLambda) / s.tauVolume) +
         s.betaStrain * unitClip(std::sqrt(strainSq) / s.tauStrain);
}

float volumeStrainSignal(std::span<const float> volumeLambda, std::span<const StrainLambda> strainLambda,
                         std::span<const Vec3> centroids, const Vec3& graspCentre, const HapticSignalSettings& s) {
  static const StrainLambda kNoStrain{};
  double weighted = 0.0, weights = 0.0;
  for (std::size_t j = 0; j < centroids.size(); ++j) {
    const float w = 1.0f / ((centroids[j] - graspCentre).norm() + s.epsilon);
    const float f = tetSignal(j < volumeLambda.size() ? volumeLambda[j] : 0.0f,
                              j < strainLambda.size() ? strainLambda[j] : kNoStrain, s);
    weighted += double(w) * f;
    weights += w;
  }
  return weights > 0.0 ? unitClip(float(weighted / weights)) : 0.0f;
}

float rawHapticForce(bool grasping, std::size_t contactCount, float contactSignal, float volumeStrain,
                     const HapticSignalSettings& s) {
  if (grasping) return unitClip(volumeStrain);
  if (contactCount > 0) return unitClip(s.betaContact * contactSignal + (1.0f - s.betaContact) * volumeStrain);
  return 0.0f;
}

float smoothHapticForce(float previous, float raw, float alphaT) {
  return unitClip((1.0f - alphaT) * unitClip(previous) + alphaT * unitClip(raw));
}

}  // namespace vrd
