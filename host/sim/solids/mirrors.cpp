#include "sim/solids/mirrors.hpp"

namespace pbflow {

namespace {
constexpr double kFarAway = 1e18;  // where an image that does not count is put: beyond every kernel

// Where the image of the particle at b (distance phi_b) lies seen from a (phi_a, normal n_a).
glm::dvec3 pair_image(const glm::dvec3& a, double phi_a, const glm::dvec3& n_a, const glm::dvec3& b, double phi_b) {
  const glm::dvec3 apart = a - b, along = apart + 2 * phi_b * n_a;
  const double d2 = std::max(glm::dot(apart, apart) + 4 * phi_a * phi_b, 0.0);
  return a - std::sqrt(d2) * (glm::dot(along, along) > 0 ? glm::normalize(along) : n_a);
}
}  // namespace

Mirrors mirrors_near(const Derived& d, const glm::dvec3& x) {
  Mirrors m;
  m.at = x;
  for (int a = 0; a < 3; ++a) {
    const double lo = x[a] - d.domain_min[a], hi = d.domain_max[a] - x[a];
    if (d.walls_mirror && std::min(lo, hi) < d.h) m.axes |= 1 << a;  // a box narrower than 2h: the nearer wall only
    m.plane2[a] = 2 * (lo <= hi ? d.domain_min[a] : d.domain_max[a]);
  }
  m.distance = d.h;
  for (const Obstacle& grown : d.obstacles) {
    const Obstacle o = grown.grown(-d.keep_out);
    glm::dvec3 normal;
    if (const double distance = o.surface(x, normal); distance < m.distance) {
      m.distance = distance;
      m.normal = normal;
      m.obstacle = o;
      m.axes |= kObstacleMirror;
    }
  }
  if (m.axes & kObstacleMirror) m.solid_velocity = m.obstacle.displacement(x - m.distance * m.normal) / d.dt;
  return m;
}

glm::dvec3 Mirrors::obstacle_image(const glm::dvec3& x, bool listed) const {
  glm::dvec3 n, unused;
  const double phi = obstacle.surface(x, n);
  const glm::dvec3 image = pair_image(at, distance, normal, x, phi);
  // An entry listed beside an obstacle that is no longer within h does not count.
  const bool inside = (axes & kObstacleMirror) &&
                      (listed || (obstacle.surface(image, unused) < 0 &&
                                  obstacle.surface(pair_image(x, phi, n, at, distance), unused) < 0));
  return inside ? image : glm::dvec3(kFarAway);
}

glm::dvec3 Mirrors::of(int k, const glm::dvec3& x, bool listed) const {
  glm::dvec3 y = k & kObstacleMirror ? obstacle_image(x, listed) : x;
  for (int a = 0; a < 3; ++a)
    if (k >> a & 1) y[a] = plane2[a] - y[a];
  return y;
}

glm::dvec3 Mirrors::velocity(int k, const glm::dvec3& v) const {
  glm::dvec3 u = v;
  if (k & kObstacleMirror) u -= 2 * glm::dot(u - solid_velocity, normal) * normal;
  for (int a = 0; a < 3; ++a)
    if (k >> a & 1) u[a] = -u[a];
  return u;
}

}  // namespace pbflow
