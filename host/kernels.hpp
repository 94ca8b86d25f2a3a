#pragma once
// SPH kernels in double precision for the reference solver and parameter set-up.
// shaders/common.glsl has the same kernels in float.
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pbflow::kernels {

inline double poly6_coef(double h) { return 315.0 / (64.0 * std::numbers::pi * std::pow(h, 9)); }
inline double spiky_coef(double h) { return 45.0 / (std::numbers::pi * std::pow(h, 6)); }

// W_poly6 for squared distance r2.
inline double poly6(double r2, double h) {
  double d = h * h - r2;
  return d > 0 ? poly6_coef(h) * d * d * d : 0.0;
}

// Gradient of W_poly6 with respect to x_i, d = x_i - x_j: what the density really changes by.
inline glm::dvec3 poly6_grad(const glm::dvec3& d, double h) {
  double t = h * h - glm::dot(d, d);
  return t > 0 ? (-6.0 * poly6_coef(h) * t * t) * d : glm::dvec3(0.0);
}

// Gradient of W_spiky with respect to x_i, d = x_i - x_j.
inline glm::dvec3 spiky_grad(const glm::dvec3& d, double h) {
  double r = glm::length(d);
  if (r <= 0 || r >= h) return glm::dvec3(0.0);
  double s = h - r;
  return (-spiky_coef(h) * s * s / r) * d;
}

// W_spiky itself (for the kernel tests: its gradient is checked against finite differences).
inline double spiky(double r, double h) {
  double s = h - r;
  return r < h ? spiky_coef(h) / 3.0 * s * s * s : 0.0;  // 15/(pi h^6) (h - r)^3
}

// The walls as the fluid's lattice continued past them (shaders/common.glsl mirrors this).
// A particle at distance a from a wall misses the layers of particles that would lie at
// a + s/2, a + 3s/2, ... beyond it (s: the spacing; the lattice's outermost centres sit
// s/2 from the wall). A layer at distance d holds a share of the poly6 sum proportional
// to l(d) = (1 - d^2/h^2)^4 (the kernel integrated over the layer's plane), so the missing
// fraction is F(a) = sum_n l(a + (n + 1/2) s) / sum_m l(m s). Counting layers, not a
// continuous slab, is what makes a lattice at rest read rho0 at a wall (the slab integral
// read +2.6 % at faces and +3.6 % at corners).
inline double layer_share(double d, double h) {
  double t = std::max(1.0 - d * d / (h * h), 0.0);
  return t * t * t * t;
}
inline double layer_share_slope(double d, double h) {  // d l / d d
  double t = std::max(1.0 - d * d / (h * h), 0.0);
  return -8.0 * d / (h * h) * t * t * t;
}
inline double lattice_layers(double h, double s) {  // sum_m l(m s) over every layer within h
  double sum = 1.0;
  for (double d = s; d < h; d += s) sum += 2.0 * layer_share(d, h);
  return sum;
}
// (F(a), dF/da) times lattice_layers(h, s): the caller divides once for all six walls.
inline glm::dvec2 wall_layers(double a, double h, double s) {
  glm::dvec2 sum(0.0);
  for (double d = std::max(a, 0.0) + 0.5 * s; d < h; d += s) sum += glm::dvec2(layer_share(d, h), layer_share_slope(d, h));
  return sum;
}

}  // namespace pbflow::kernels
