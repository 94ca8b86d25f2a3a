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

// The weight of lambda's average over the neighbours (constraint_smooth.comp), 1 - (r/h)^8:
// nearly flat inside h, where a flat weight smooths the worst modes most, and 0 at h, so that
// a neighbour crossing h changes the average smoothly. Unnormalised (the average divides).
inline double smoothing_weight(const glm::dvec3& d, double h) {
  const double t = glm::dot(d, d) / (h * h), t2 = t * t;
  return std::max(1.0 - t2 * t2, 0.0);
}

// The weight of the smoothed positions' neighbourhood mean (smoothed_positions.comp), 1 - (r/h)^3
// (Yu & Turk 2013's): falling from the centre, so that a particle's nearest neighbours count
// most. The flatter 1 - (r/h)^8 left the settled tank's top at 3.8 degrees in the normals
// view where this leaves 3.0. Unnormalised (the mean divides).
inline double position_weight(const glm::dvec3& d, double h) {
  const double t = glm::length(d) / h;
  return std::max(1.0 - t * t * t, 0.0);
}

}  // namespace pbflow::kernels
