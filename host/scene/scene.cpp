#include "scene/scene.hpp"

#include <algorithm>
#include <cmath>

namespace pbflow {

double fluid_volume(const Scene& scene) {
  double v = 0;
  for (const Box& b : scene.fluid_blocks) v += (b.max.x - b.min.x) * (b.max.y - b.min.y) * (b.max.z - b.min.z);
  for (const Ball& b : scene.fluid_spheres) v += 4.0 / 3.0 * M_PI * b.radius * b.radius * b.radius;
  return v;
}

double particle_estimate(const Scene& scene) { return fluid_volume(scene) / std::pow(scene.particle_spacing, 3); }

double fall_speed(const Scene& scene) {
  return std::sqrt(2.0 * glm::length(scene.gravity) * (scene.domain.max.y - scene.domain.min.y));
}

double tank_speed(const Scene& scene) {
  const Motion& m = scene.tank_motion;
  return m.moves() ? m.top_speed(reach(scene.domain.min, scene.domain.max, m.centre)) : 0.0;
}

double solid_speed(const Scene& scene) {
  double top = tank_speed(scene);
  for (const Obstacle& o : scene.obstacles)
    if (o.motion.moves()) top = std::max(top, o.motion.top_speed(glm::length(o.middle() - o.motion.centre) + o.extent()));
  return top;
}

int chosen_substeps(const Scene& scene) {
  constexpr double kRealTimeStep = 1.0 / 120.0, kRounding = 1e-9;
  const double h = scene.solver.kernel_ratio * scene.particle_spacing;
  double emitted = 0;  // the fastest emitter's speed, a kernel radius a step like a fall
  for (const Emitter& e : scene.emitters) emitted = std::max(emitted, e.speed);
  const double n = std::max({1.0 / (scene.fps * kRealTimeStep), std::max(fall_speed(scene), emitted) / (scene.fps * h),
                             solid_speed(scene) / (scene.fps * kSolidStep * scene.particle_spacing)});
  return int(std::clamp(std::ceil(n - kRounding), 1.0, 1000.0));
}

}  // namespace pbflow
