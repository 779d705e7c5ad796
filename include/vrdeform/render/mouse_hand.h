#pragma once
// The mouse as a hand (`vrdeform view`): fingertip centres given directly to the simulation
// (HandFrame::direct), computed on the UI thread each frame from the cursor and the posed scene.
//
// - Poke: press the left button over a body; the index fingertip appears touching the surface
//   under the cursor and sinks in along the view ray to `pokeDepth` fingertip radii over
//   `pressSeconds`; it follows the cursor across the body while held and withdraws on release.
// - Pinch: hold the grasp key over a body; thumb and index come from either side of it along the
//   screen's horizontal and close on it until the grasp takes hold; moving the cursor moves the
//   pinch in the plane facing the camera (up lifts the body); releasing the key opens the hand.
// Fingers not in use wait far above the scene, where they touch nothing.

#include <array>

#include "vrdeform/interact/hand.h"
#include "vrdeform/render/posed_scene.h"

namespace vrd {

struct MouseHandSettings {
  float pokeDepth = 1.0f;      ///< how far a poke presses in, in fingertip radii
  float pressSeconds = 0.5f;   ///< time to reach pokeDepth
  float pinchDepth = 1.0f;     ///< how far each pinching fingertip closes past the surface, in radii
  float closingSpeed = 0.03f;  ///< of the pinch aperture (m/s), closing and opening
};

struct MouseState {
  float x = 0, y = 0;  ///< cursor (pixels, y down)
  int width = 1, height = 1;
  bool poke = false;   ///< left button held (and not taken by the UI)
  bool pinch = false;  ///< grasp key held
};

class MouseHand {
 public:
  /// `radius`: the fingertips'; `park`: where unused fingers wait (away from every body).
  MouseHand(float radius, const Vec3& park);

  /// Advances by `dt` seconds of UI time and returns the hand to send.
  HandFrame update(const MouseState& mouse, const PosedScene& scene, const OrbitCamera& camera, float dt);
  /// Fingers in use (to draw): the index while poking, thumb and index while pinching.
  const std::array<bool, kFingerCount>& active() const { return active_; }
  bool busy() const { return mode_ != Mode::Idle; }

  MouseHandSettings settings;

 private:
  enum class Mode { Idle, Poke, Pinch, Opening };
  HandFrame parked() const;

  float radius_;
  Vec3 park_;
  Mode mode_ = Mode::Idle;
  std::array<bool, kFingerCount> active_{};
  float held_ = 0.0f;      // seconds the poke has been held
  float hitDepth_ = 0.0f;  // poke: distance from the eye to the surface at the press
  // Pinch: centre and axis at the start, its plane, and the aperture now, closed and fully open.
  Vec3 centre_ = Vec3::Zero(), axis_ = Vec3::UnitX(), grabbed_ = Vec3::Zero();
  float aperture_ = 0.0f, closed_ = 0.0f, open_ = 0.0f;
  Vec3 shift_ = Vec3::Zero();
};

}  // namespace vrd
