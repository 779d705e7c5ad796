// Drops a soft cube on the ground for one second; exits 0 when it landed and stayed whole.
#include <cstdio>

#include <vrdeform/mesh/primitives.h>
#include <vrdeform/sim/world.h>

int main() {
  vrd::World world;
  vrd::Material material;
  material.elastic = vrd::ElasticModuli{5e3f, 0.4f, 1000.0f, 0.002f};
  const auto model =
      vrd::makeSoftBody(vrd::makeBoxTets(vrd::Vec3::Zero(), vrd::Vec3::Constant(0.1f), 3, 3, 3), material);
  const vrd::BodyId body = world.addBody(model, vrd::Vec3(0.0f, 0.05f, 0.0f));
  world.addCollider(vrd::Collider::plane(vrd::Vec3::UnitY()));
  for (int step = 0; step < 60; ++step) world.step();
  const float y = world.particles().x[world.particleIndex(body, 0)].pos.y();
  std::printf("bottom corner at y = %.4f m, volume loss %.2f%%\n", y, 100.0 * world.volumeLoss(body));
  return y > -0.001f && y < 0.01f && world.takeEvents().empty() ? 0 : 1;
}
