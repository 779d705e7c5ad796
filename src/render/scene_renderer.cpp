#include "vrdeform/render/scene_renderer.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "gl_program.h"

namespace vrd {
namespace {

constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in float aValue;
uniform mat4 uViewProjection;
uniform mat4 uModel;
uniform mat3 uNormalMatrix;
out vec3 vPosition;
out vec3 vNormal;
out float vValue;
void main() {
  vec4 world = uModel * vec4(aPosition, 1.0);
  vPosition = world.xyz;
  vNormal = uNormalMatrix * aNormal;
  vValue = aValue;
  gl_Position = uViewProjection * world;
}
)";

// uMode: 0 plain colour, 1 colour map (blue - white - red over [-uRange, uRange]), 2 checkered ground,
// 3 a shadow on that ground (its checker, darkened; opaque, so overlapping triangles draw it once).
constexpr const char* kFragmentShader = R"(#version 330 core
in vec3 vPosition;
in vec3 vNormal;
in float vValue;
uniform vec3 uColor;
uniform vec3 uEye;
uniform vec3 uLight;
uniform int uMode;
uniform float uRange;
uniform float uCell;
out vec4 fragColor;
void main() {
  vec3 n = normalize(vNormal);
  if (!gl_FrontFacing) n = -n;  // cloth and the inside of an opened body are lit from the viewer's side
  vec3 toEye = normalize(uEye - vPosition);
  vec3 base = uColor;
  if (uMode == 1) {
    float t = clamp(vValue / uRange, -1.0, 1.0);
    vec3 mid = vec3(0.92);
    base = t < 0.0 ? mix(mid, vec3(0.15, 0.35, 0.95), -t) : mix(mid, vec3(0.9, 0.15, 0.1), t);
  } else if (uMode >= 2) {
    vec3 cell = floor(vPosition / uCell);
    base = mod(cell.x + cell.y + cell.z, 2.0) < 1.0 ? uColor : uColor * 0.8;
    if (uMode == 3) {
      fragColor = vec4(0.42 * base, 1.0);  // about the ambient share of the lit ground
      return;
    }
  }
  float diffuse = max(dot(n, uLight), 0.0);
  float specular = pow(max(dot(n, normalize(uLight + toEye)), 0.0), 40.0);
  vec3 c = base * (0.28 + 0.72 * diffuse) + vec3(0.12 * specular);
  fragColor = vec4(c, 1.0);
}
)";

constexpr GLuint kPosition = 0, kNormal = 1, kValue = 2;

// A vertex array with its position, normal and value buffers and its triangles.
struct GlMesh {
  GLuint vao = 0, buffers[4] = {0, 0, 0, 0};  // positions, normals, values, indices
  GLsizei indexCount = 0;
  std::size_t vertexCount = 0;

  GlMesh(std::span<const Triangle> triangles, std::size_t vertices) : vertexCount(vertices) {
    glGenVertexArrays(1, &vao);
    glGenBuffers(4, buffers);
    glBindVertexArray(vao);
    const auto attribute = [&](GLuint location, GLuint buffer, int size) {
      glBindBuffer(GL_ARRAY_BUFFER, buffer);
      glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices * size * sizeof(float)), nullptr, GL_DYNAMIC_DRAW);
      glEnableVertexAttribArray(location);
      glVertexAttribPointer(location, size, GL_FLOAT, GL_FALSE, 0, nullptr);
    };
    attribute(kPosition, buffers[0], 3);
    attribute(kNormal, buffers[1], 3);
    attribute(kValue, buffers[2], 1);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffers[3]);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(triangles.size_bytes()), triangles.data(), GL_STATIC_DRAW);
    indexCount = GLsizei(triangles.size() * 3);
    glBindVertexArray(0);
  }
  ~GlMesh() {
    glDeleteBuffers(4, buffers);
    glDeleteVertexArrays(1, &vao);
  }
  GlMesh(const GlMesh&) = delete;
  GlMesh& operator=(const GlMesh&) = delete;

  void upload(std::span<const Vec3> positions, std::span<const Vec3> normals, std::span<const float> values) const {
    static_assert(sizeof(Vec3) == 3 * sizeof(float));
    glBindBuffer(GL_ARRAY_BUFFER, buffers[0]);
    glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(positions.size_bytes()), positions.data());
    glBindBuffer(GL_ARRAY_BUFFER, buffers[1]);
    glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(normals.size_bytes()), normals.data());
    glBindBuffer(GL_ARRAY_BUFFER, buffers[2]);
    glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(values.size_bytes()), values.data());
  }
  void draw() const {
    glBindVertexArray(vao);
    glDrawElements(GL_TRIANGLES, indexCount, GL_UNSIGNED_INT, nullptr);
  }
};

// A static shape (unit sphere, unit cube, unit square) uploaded once.
std::unique_ptr<GlMesh> staticMesh(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                                   const std::vector<Triangle>& triangles) {
  auto mesh = std::make_unique<GlMesh>(triangles, positions.size());
  const std::vector<float> values(positions.size(), 0.0f);
  mesh->upload(positions, normals, values);
  return mesh;
}

std::unique_ptr<GlMesh> unitSphere() {
  const int rings = 16, segments = 24;
  std::vector<Vec3> p;
  std::vector<Triangle> t;
  for (int i = 0; i <= rings; ++i) {
    const float theta = std::numbers::pi_v<float> * float(i) / rings;
    for (int j = 0; j <= segments; ++j) {
      const float phi = 2.0f * std::numbers::pi_v<float> * float(j) / segments;
      p.emplace_back(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
    }
  }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const Index a = Index(i * (segments + 1) + j), b = a + Index(segments + 1);
      t.push_back({a, a + 1, b});
      t.push_back({a + 1, b + 1, b});
    }
  return staticMesh(p, p, t);
}

std::unique_ptr<GlMesh> unitCube() {  // [-1, 1]^3, four vertices per face for flat normals
  std::vector<Vec3> p, n;
  std::vector<Triangle> t;
  for (int axis = 0; axis < 3; ++axis)
    for (float side : {-1.0f, 1.0f}) {
      Vec3 normal = Vec3::Zero();
      normal[axis] = side;
      const Vec3 u = Vec3::Unit((axis + 1) % 3), v = side * Vec3::Unit((axis + 2) % 3);
      const Index first = Index(p.size());
      for (const auto& [a, b] : {std::pair{-1.0f, -1.0f}, {1.0f, -1.0f}, {1.0f, 1.0f}, {-1.0f, 1.0f}}) {
        p.push_back(normal + a * u + b * v);
        n.push_back(normal);
      }
      t.push_back({first, first + 1, first + 2});
      t.push_back({first, first + 2, first + 3});
    }
  return staticMesh(p, n, t);
}

std::unique_ptr<GlMesh> unitSquare() {  // in the xz plane, facing +y
  const std::vector<Vec3> p{{-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}};
  const std::vector<Vec3> n(4, Vec3::UnitY());
  return staticMesh(p, n, {{0, 1, 2}, {0, 2, 3}});
}

Eigen::Matrix4f affine(const Mat3& linear, const Vec3& translation) {
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m.block<3, 3>(0, 0) = linear;
  m.block<3, 1>(0, 3) = translation;
  return m;
}

Vec3 mix(const Vec3& a, const Vec3& b, float t) { return a + std::clamp(t, 0.0f, 1.0f) * (b - a); }

}  // namespace

Vec3 bodyColor(BodyId body) {
  static const Vec3 palette[] = {{0.80f, 0.42f, 0.36f},
                                 {0.36f, 0.58f, 0.82f},
                                 {0.52f, 0.76f, 0.40f},
                                 {0.88f, 0.72f, 0.32f},
                                 {0.66f, 0.48f, 0.80f}};
  return palette[body % std::size(palette)];
}

struct SceneRenderer::Gl {
  GlProgram program{kVertexShader, kFragmentShader};
  std::vector<std::unique_ptr<GlMesh>> meshes;
  std::unique_ptr<GlMesh> sphere = unitSphere(), cube = unitCube(), square = unitSquare();
};

SceneRenderer::SceneRenderer(const PosedScene& scene) : gl_(std::make_unique<Gl>()) {
  for (std::size_t i = 0; i < scene.meshCount(); ++i)
    gl_->meshes.push_back(std::make_unique<GlMesh>(scene.mesh(i).triangles, scene.mesh(i).vertexCount()));
}

SceneRenderer::~SceneRenderer() = default;

void SceneRenderer::draw(const PosedScene& scene, const Snapshot& snapshot, const OrbitCamera& camera, int width,
                         int height, const RenderSettings& settings) {
  glViewport(0, 0, width, height);
  glClearColor(settings.background.x(), settings.background.y(), settings.background.z(), 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);

  const GlProgram& p = gl_->program;
  p.use();
  p.set("uViewProjection",
        Eigen::Matrix4f(camera.projection(float(width) / float(std::max(height, 1))) * camera.view()));
  p.set("uEye", camera.eye());
  // A key light over the viewer's shoulder.
  p.set("uLight", Vec3(-camera.forward() + 0.6f * camera.up() - 0.3f * camera.right()).normalized());
  p.set("uRange", std::max(settings.colorRange, 1e-6f));
  const auto place = [&](const Mat3& linear, const Vec3& translation) {
    p.set("uModel", affine(linear, translation));
    const Mat3 normalMatrix = linear.determinant() != 0.0f ? Mat3(linear.inverse().transpose()) : Mat3::Identity();
    p.set("uNormalMatrix", normalMatrix);
  };

  // Bodies.
  place(Mat3::Identity(), Vec3::Zero());
  for (std::size_t i = 0; i < scene.meshCount(); ++i) {
    const GlMesh& mesh = *gl_->meshes[i];
    mesh.upload(scene.positions(i), scene.normals(i), scene.values(i));
    p.set("uMode", settings.colorMap == ColorMap::None ? 0 : 1);
    p.set("uColor", bodyColor(scene.mesh(i).body));
    mesh.draw();
  }

  // Fingertips: grey in the air, redder with their force; green while a grasp holds.
  p.set("uMode", 0);
  if (settings.fingertips && snapshot.fingertipRadius > 0.0f)
    for (int f = 0; f < kFingerCount; ++f) {
      if (!snapshot.fingerPresent[f] || !settings.showFinger[f]) continue;
      const float force = snapshot.haptics.fingers[f].force;
      Vec3 color = mix(Vec3(0.75f, 0.75f, 0.72f), Vec3(0.95f, 0.2f, 0.15f), force);
      if (snapshot.grasping) color = mix(color, Vec3(0.3f, 0.85f, 0.4f), 0.6f);
      p.set("uColor", color);
      place(snapshot.fingertipRadius * Mat3::Identity(), snapshot.fingertips[f]);
      gl_->sphere->draw();
    }

  // The bodies' and fingertips' shadows on a ground plane {x : n.x = offset}: flattened onto it
  // along a fixed light from above (so they fall under what casts them, grounding it), lifted by
  // `lift` above the plane's square.
  const auto drawShadows = [&](const Vec3& n, float offset, const Vec3& across, float lift) {
    const Vec3 light = (n + 0.25f * n.cross(across) + 0.15f * across).normalized();
    const Mat3 flatten = Mat3::Identity() - light * n.transpose() / n.dot(light);
    const Vec3 shift = light * (offset / n.dot(light)) + lift * n;
    p.set("uMode", 3);
    place(flatten, shift);
    for (std::size_t i = 0; i < scene.meshCount(); ++i) gl_->meshes[i]->draw();
    if (settings.fingertips && snapshot.fingertipRadius > 0.0f)
      for (int f = 0; f < kFingerCount; ++f)
        if (snapshot.fingerPresent[f] && settings.showFinger[f]) {
          place(flatten * snapshot.fingertipRadius, flatten * snapshot.fingertips[f] + shift);
          gl_->sphere->draw();
        }
  };

  // Colliders; planes become a checkered square around the bodies.
  if (settings.colliders) {
    const Eigen::AlignedBox3f& box = scene.bounds();
    const float extent = box.isEmpty() ? 1.0f : std::max(box.diagonal().norm(), 1e-3f);
    const Vec3 centre = box.isEmpty() ? Vec3(Vec3::Zero()) : Vec3(box.center());
    for (const Collider& c : scene.colliders()) {
      p.set("uColor", Vec3(0.55f, 0.56f, 0.58f));
      if (c.shape == ColliderShape::Plane) {
        const Vec3 n = c.normal.normalized();
        const Vec3 a = (std::abs(n.x()) < 0.9f ? Vec3::UnitX() : Vec3::UnitZ()).cross(n).normalized();
        Mat3 basis;
        basis << n.cross(a), n, a;  // columns: the square's x, y (its normal) and z
        const Vec3 onPlane = centre - n * n.dot(centre - c.center);
        p.set("uMode", 2);
        p.set("uCell", 0.25f * extent);
        place(basis * (8.0f * extent), onPlane);
        gl_->square->draw();
        drawShadows(n, n.dot(c.center), a, 1e-3f * extent);
        p.set("uMode", 0);
      } else if (c.shape == ColliderShape::Sphere) {
        place(c.radius * Mat3::Identity(), c.center);
        gl_->sphere->draw();
      } else {
        place(c.rotation * c.halfExtents.asDiagonal(), c.center);
        gl_->cube->draw();
      }
    }
  }
  glBindVertexArray(0);
  glUseProgram(0);
}

}  // namespace vrd
