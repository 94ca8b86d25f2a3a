#include "scene/seeding.hpp"

#include <algorithm>
#include <random>

namespace pbflow {

namespace {
// The lattice points, each moved by up to `jitter` spacings along each axis; the obstacles are
// kept out of the moved points.
std::vector<glm::dvec3> seed(const Scene& scene, double jitter) {
  const double s = scene.particle_spacing;
  std::mt19937_64 random(uint64_t(scene.seed));
  std::uniform_real_distribution<double> offset(-jitter * s, jitter * s);
  auto moved = [&](glm::dvec3 x) {
    for (int axis = 0; axis < 3; ++axis) x[axis] += offset(random);
    return x;
  };
  std::vector<Obstacle> keep_out;
  for (const Obstacle& o : scene.obstacles) keep_out.push_back(o.grown(0.5 * s));
  auto in_box = [](const glm::dvec3& x, const Box& b) {
    return glm::all(glm::greaterThanEqual(x, b.min)) && glm::all(glm::lessThan(x, b.max));
  };
  auto outside_obstacles = [&](const glm::dvec3& x) {
    return std::none_of(keep_out.begin(), keep_out.end(), [&](const Obstacle& o) { return o.contains(x); });
  };
  std::vector<glm::dvec3> points;
  for (size_t b = 0; b < scene.fluid_blocks.size(); ++b) {
    const Box& box = scene.fluid_blocks[b];
    glm::ivec3 n = glm::ivec3(glm::floor((box.max - box.min) / s + 1e-9));
    for (int k = 0; k < n.z; ++k)
      for (int j = 0; j < n.y; ++j)
        for (int i = 0; i < n.x; ++i) {
          glm::dvec3 x = box.min + s * (glm::dvec3(i, j, k) + 0.5);
          bool earlier = false;
          for (size_t e = 0; e < b && !earlier; ++e) earlier = in_box(x, scene.fluid_blocks[e]);
          if (earlier) continue;
          if (glm::dvec3 m = moved(x); outside_obstacles(m)) points.push_back(m);
        }
  }
  for (size_t b = 0; b < scene.fluid_spheres.size(); ++b) {
    const Ball& ball = scene.fluid_spheres[b];
    glm::ivec3 lo = glm::ivec3(glm::floor((ball.centre - ball.radius - scene.domain.min) / s));
    glm::ivec3 hi = glm::ivec3(glm::ceil((ball.centre + ball.radius - scene.domain.min) / s));
    for (int k = lo.z; k <= hi.z; ++k)
      for (int j = lo.y; j <= hi.y; ++j)
        for (int i = lo.x; i <= hi.x; ++i) {
          glm::dvec3 x = scene.domain.min + s * (glm::dvec3(i, j, k) + 0.5);
          if (glm::length(x - ball.centre) >= ball.radius) continue;
          bool earlier = std::any_of(scene.fluid_blocks.begin(), scene.fluid_blocks.end(),
                                     [&](const Box& box) { return in_box(x, box); });
          for (size_t e = 0; e < b && !earlier; ++e)
            earlier = glm::length(x - scene.fluid_spheres[e].centre) < scene.fluid_spheres[e].radius;
          if (earlier) continue;
          if (glm::dvec3 m = moved(x); outside_obstacles(m)) points.push_back(m);
        }
  }
  if (points.empty())
    throw InputError("the fluid holds no particle: its blocks and spheres hold no lattice point at this particle_spacing "
                     "outside the obstacles and the domain's mesh");
  return points;
}

}  // namespace

std::vector<glm::dvec3> lattice_particles(const Scene& scene) { return seed(scene, 0.0); }

std::vector<glm::dvec3> initial_particles(const Scene& scene) { return seed(scene, kSeedJitter); }

}  // namespace pbflow
