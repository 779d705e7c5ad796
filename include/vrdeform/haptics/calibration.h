#pragma once
// Automatic calibration of the haptic scales tau^C, tau^V, tau^S (eqs. 40-41). The multipliers'
// magnitudes depend on the material, the mesh and the time step, so instead of tuning them by
// hand the user's world is poked in a standard way (on a copy) and the tau are set so that this
// standard poke reaches a chosen level of the signal.
//
// Standard poke: a fingertip sphere comes down along gravity onto the body's highest particle and
// presses `depth` (default: one fingertip radius) below it over `duration`, then holds for half
// that time. At the end, tau^C is the mean contact multiplier over `contactTarget` (the finger's
// summed multipliers over it for tauFingerContact), and tau^V,
// tau^S (in the ratio of their inverse-distance-weighted means around the fingertip) are scaled
// so that F_VS equals `volumeStrainTarget`.

#include <functional>
#include <optional>

#include "vrdeform/haptics/haptic_signal.h"
#include "vrdeform/sim/world.h"

namespace vrd {

struct CalibrationSettings {
  float radius = 0.009f;                                           ///< fingertip radius (m)
  FingertipContactMode contact = FingertipContactMode::Particles;  ///< as the hand that will use the result
  FingertipFriction friction;                                      ///< as the hand that will use the result
  float depth = 0.0f;                                              ///< indentation (m); 0 = the radius
  float duration = 1.0f;                                           ///< loading time (s)
  /// The standard poke's contact term (eq. 40) and F_VS (eq. 42): half of full scale, so the
  /// contact term clips only at twice the standard poke's multipliers and a deeper press still
  /// feels deeper (the standard poke reads 0.45 with the default betas).
  float contactTarget = 0.5f;
  float volumeStrainTarget = 0.4f;
  std::optional<Vec3> point;        ///< poke this surface point instead of the highest particle
  std::function<bool()> stop = {};  ///< polled after each step of the poke: true ends it with vrd::Stopped
};

struct HapticCalibration {
  HapticSignalSettings signal;  ///< the given settings with the three tau replaced
  Vec3 point;                   ///< where the poke touched
  Vec3 direction;               ///< unit direction it pressed in
  float depth = 0.0f;           ///< indentation reached (m)
  float force = 0.0f;           ///< contact force at full depth (N)
  std::size_t contacts = 0;     ///< contacts at full depth
};

/// Pokes a copy of `world` (the original is not touched; its own fingertips are switched off in
/// the copy). Throws vrd::Error when the poke makes no contact or the body gives way as a whole
/// (a body needs support, e.g. ground or pins, to be calibrated).
HapticCalibration calibrateHaptics(const World& world, BodyId body, const HapticSignalSettings& base = {},
                                   const CalibrationSettings& settings = {});

}  // namespace vrd
