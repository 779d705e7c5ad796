#include "vrdeform/haptics/haptic_signal.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "vrdeform/math/lanes.h"

namespace vrd {

// clampUnit (math/types.h) maps NaN to 0 as well: a broken multiplier must not reach the glove.

float normalisedContact(float lambdaSum, std::size_t contactCount, float tauContact) {
  if (contactCount == 0) return 0.0f;
  return clampUnit(std::abs(lambdaSum) / (float(contactCount) * tauContact));
}

namespace {

// Eqs. 41-42 given |lambda^S|^2, for one tet (T = float) or four (Lane4). Both clips map NaN to 0.
template <typename T>
T signalOf(T volumeLambda, T strainSq, const HapticSignalSettings& s) {
  const T zero = splat<T>(0.0), one = splat<T>(1.0);
  const auto clip = [&](T v) { return select(v > zero, select(v < one, v, one), zero); };
  const T volume = select(volumeLambda < zero, -volumeLambda, volumeLambda);
  return s.betaVolume * clip(volume / s.tauVolume) + s.betaStrain * clip(sqrt(strainSq) / s.tauStrain);
}

// One float (T = float) or four at p.
template <typename T>
T loadAt(const float* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// The signals of tets j, j + 1, ... (one per lane of T) of a body of n tets (tetSignals).
template <typename T>
T signalsAt(std::span<const float> volume, std::span<const float> strain, std::size_t n, std::size_t j,
            const HapticSignalSettings& s) {
  T strainSq = splat<T>(0.0);
  if (strain.size() >= kStrainComponents * n)
    for (int k = 0; k < kStrainComponents; ++k) {
      const T l = loadAt<T>(&strain[std::size_t(k) * n + j]);
      strainSq += l * l;
    }
  return signalOf(volume.size() >= n ? loadAt<T>(&volume[j]) : splat<T>(0.0), strainSq, s);
}

// w_j = 1 / (d_j + epsilon) of tets j, j + 1, ... (one per lane of T) seen from `centre` (eq. 42).
template <typename T>
T inverseDistanceAt(const TetSignals& tets, std::size_t j, const Vec3& centre, float epsilon) {
  const T dx = loadAt<T>(&tets.x[j]) - centre.x(), dy = loadAt<T>(&tets.y[j]) - centre.y(),
          dz = loadAt<T>(&tets.z[j]) - centre.z();
  return 1.0f / (sqrt(dx * dx + dy * dy + dz * dz) + epsilon);
}

}  // namespace

float tetSignal(float volumeLambda, const StrainLambda& strainLambda, const HapticSignalSettings& s) {
  float strainSq = 0.0f;
  for (float l : strainLambda) strainSq += l * l;
  return signalOf(volumeLambda, strainSq, s);
}

void tetSignals(std::span<const float> volume, std::span<const float> strain, const HapticSignalSettings& s,
                std::span<float> out) {
  const std::size_t n = out.size();
  std::size_t j = 0;
  for (; j + 4 <= n; j += 4) {
    const Lane4 f = signalsAt<Lane4>(volume, strain, n, j, s);
    std::memcpy(&out[j], &f, sizeof f);
  }
  for (; j < n; ++j) out[j] = signalsAt<float>(volume, strain, n, j, s);
}

float volumeStrainSignal(const TetSignals& tets, const Vec3& graspCentre, float epsilon) {
  // Four tets at a time in float; the lanes' sums go into doubles every kBlock tets: summed in
  // float lanes throughout, 10^6 tets would be off by 5e-6.
  constexpr std::size_t kBlock = 256;
  const std::size_t n = tets.size();
  double weighted = 0.0, weights = 0.0;
  std::size_t j = 0;
  while (j + 4 <= n) {
    const std::size_t blockEnd = std::min(n, j + kBlock);
    Lane4 w4{}, wf4{};
    for (; j + 4 <= blockEnd; j += 4) {
      const Lane4 w = inverseDistanceAt<Lane4>(tets, j, graspCentre, epsilon);
      w4 += w;
      wf4 += w * loadAt<Lane4>(&tets.f[j]);
    }
    for (int l = 0; l < 4; ++l) weights += w4[l], weighted += wf4[l];
  }
  for (; j < n; ++j) {
    const float w = inverseDistanceAt<float>(tets, j, graspCentre, epsilon);
    weights += w;
    weighted += w * tets.f[j];
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
