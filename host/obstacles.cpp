#include "obstacles.hpp"

#include <limits>

namespace pbflow {

bool Obstacle::contains(const glm::dvec3& x) const {
  if (kind == Kind::Sphere) return glm::length(x - centre) < radius;
  return glm::all(glm::greaterThan(x, min)) && glm::all(glm::lessThan(x, max));
}

Obstacle Obstacle::grown(double margin) const {
  Obstacle o = *this;
  o.min -= margin;
  o.max += margin;
  o.radius += margin;
  return o;
}

glm::dvec3 project_out(const Obstacle& o, const glm::dvec3& x, const glm::dvec3& wall_min,
                       const glm::dvec3& wall_max) {
  if (!o.contains(x)) return x;
  if (o.kind == Obstacle::Kind::Sphere) {
    glm::dvec3 d = x - o.centre;
    double r = glm::length(d);
    return o.centre + o.radius * (r > 0 ? d / r : glm::dvec3(0, 1, 0));  // the centre itself goes up
  }
  glm::dvec3 best = x;
  double nearest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (o.min[k] >= wall_min[k] && x[k] - o.min[k] < nearest) {
      nearest = x[k] - o.min[k];
      best = x;
      best[k] = o.min[k];
    }
    if (o.max[k] <= wall_max[k] && o.max[k] - x[k] < nearest) {
      nearest = o.max[k] - x[k];
      best = x;
      best[k] = o.max[k];
    }
  }
  return best;
}

std::vector<glm::vec4> pack_obstacles(const std::vector<Obstacle>& obstacles) {
  std::vector<glm::vec4> data{glm::vec4(float(obstacles.size()), 0, 0, 0)};
  for (const Obstacle& o : obstacles) {
    if (o.kind == Obstacle::Kind::Sphere) {
      data.emplace_back(glm::vec3(o.centre), 1.0f);
      data.emplace_back(float(o.radius), 0.0f, 0.0f, 0.0f);
    } else {
      data.emplace_back(glm::vec3(o.min), 0.0f);
      data.emplace_back(glm::vec3(o.max), 0.0f);
    }
  }
  return data;
}

}  // namespace pbflow
