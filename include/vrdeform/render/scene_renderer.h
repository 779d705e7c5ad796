#pragma once
// Draws a posed scene with OpenGL 3.3 core: the bodies lit, in their own colours or a colour map,
// cloth from both sides, the fingertips coloured by their force (the pinching ones by the grasp),
// and the colliders (a checkered ground). The same code draws into a window and, headless, into a
// Framebuffer; it needs a current context and must be used on that context's thread.

#include <memory>

#include "vrdeform/render/orbit_camera.h"
#include "vrdeform/render/posed_scene.h"

namespace vrd {

struct RenderSettings {
  ColorMap colorMap = ColorMap::None;  ///< PosedScene::pose() must have computed the same map
  float colorRange = 0.02f;            ///< |value| drawn at full colour (blue below 0, red above)
  bool fingertips = true;
  std::array<bool, kFingerCount> showFinger{true, true, true, true, true};  ///< of the fingers present
  bool colliders = true;
  Vec3 background{0.13f, 0.14f, 0.17f};  ///< clear colour (linear RGB in [0, 1])
};

/// A body's colour when no colour map is on.
Vec3 bodyColor(BodyId body);

class SceneRenderer {
 public:
  /// Uploads the meshes' triangles. Throws vrd::Error when the shaders do not build.
  explicit SceneRenderer(const PosedScene& scene);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  /// Clears the viewport (0, 0, width, height) of the bound framebuffer and draws `scene` as last
  /// posed, with the hand of `snapshot`.
  void draw(const PosedScene& scene, const Snapshot& snapshot, const OrbitCamera& camera, int width, int height,
            const RenderSettings& settings);

 private:
  struct Gl;
  std::unique_ptr<Gl> gl_;
};

}  // namespace vrd
