#pragma once
// SPH kernels in double precision for the reference solver and parameter set-up.
// shaders/common.glsl has the same kernels in float.
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pbflow::kernels {

// Written in q = r/h with the powers of h in one factor, 1/h^3 for W and 1/h^4 for its
// gradient: the textbook 315/(64 pi h^9) (h^2 - r^2)^3 leaves float's range below h ~ 6e-5 m
// and above h ~ 2e4 m (1/h^9 overflows or underflows), and the shaders run in float.
inline double poly6_scale(double h) { return 315.0 / (64.0 * std::numbers::pi * h * h * h); }
inline double spiky_grad_scale(double h) { return 45.0 / (std::numbers::pi * h * h * h * h); }

// W_poly6 for squared distance r2: poly6_scale (1 - r^2/h^2)^3.
inline double poly6(double r2, double h) {
  const double d = 1.0 - r2 / (h * h);
  return d > 0 ? poly6_scale(h) * d * d * d : 0.0;
}

// Gradient of W_poly6 with respect to x_i, d = x_i - x_j: what the density really changes by.
inline glm::dvec3 poly6_grad(const glm::dvec3& d, double h) {
  const double t = 1.0 - glm::dot(d, d) / (h * h);
  return t > 0 ? (-6.0 * poly6_scale(h) / (h * h) * t * t) * d : glm::dvec3(0.0);
}

// Gradient of W_spiky with respect to x_i, d = x_i - x_j: spiky_grad_scale times its shape,
// -(1 - r/h)^2 d/r, which alone serves where only a direction is wanted (the vorticity force).
inline glm::dvec3 spiky_grad_shape(const glm::dvec3& d, double h) {
  const double r = glm::length(d);
  if (r <= 0 || r >= h) return glm::dvec3(0.0);
  const double s = 1.0 - r / h;
  return (-s * s / r) * d;
}
inline glm::dvec3 spiky_grad(const glm::dvec3& d, double h) { return spiky_grad_scale(h) * spiky_grad_shape(d, h); }

// W_spiky itself (for the kernel tests: its gradient is checked against finite differences).
inline double spiky(double r, double h) {
  const double s = 1.0 - r / h;
  return r < h ? spiky_grad_scale(h) * h / 3.0 * s * s * s : 0.0;  // 15/(pi h^6) (h - r)^3
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
