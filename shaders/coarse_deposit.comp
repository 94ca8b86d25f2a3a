#version 450
// The coarse correction, 1 of 5 (contract.h): each particle's weight and compression past
// the floor, max(rho/rho0 - 1 - COARSE_FLOOR, 0) at x_pred, spread over the eight coarse nodes around it
// (cloud-in-cell), summed in fixed point by atomics, and the walls it touches (contract.h,
// COARSE_WORDS). The buffer is cleared before.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "contract.h"
#include "coarse.glsl"

layout(std430, binding = 5) readonly buffer XPred { vec4 x_pred[]; };
layout(std430, binding = 6) readonly buffer Rho { float rho[]; };
layout(std430, binding = 7) buffer Sums { uint sums[]; };  // per node: filled, excess, walls touched

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  float compression = clamp(rho[i] / sim.rho0 - 1.0 - COARSE_FLOOR, 0.0, COARSE_MAX_COMPRESSION);
  vec3 x = x_pred[i].xyz;
  uint touched = 0u;
  for (int a = 0; a < 3; ++a) {
    if (x[a] - sim.wall_min[a] < 0.25 * sim.h) touched |= 1u << (2 * a);
    if (sim.wall_max[a] - x[a] < 0.25 * sim.h) touched |= 2u << (2 * a);
  }
  CoarseCorner c = coarse_corner(x);
  for (int k = 0; k < 8; ++k) {
    float w;
    int node = coarse_node(c, k, w);
    atomicAdd(sums[COARSE_WORDS * node], uint(w * COARSE_UNIT + 0.5));
    if (compression > 0.0) atomicAdd(sums[COARSE_WORDS * node + 1], uint(w * compression * COARSE_UNIT + 0.5));
  }
  if (touched != 0u) atomicOr(sums[COARSE_WORDS * coarse_node_at(x) + 2], touched);
}
