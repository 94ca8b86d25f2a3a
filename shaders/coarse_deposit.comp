#version 450
// The coarse correction, 1 of 5 (contract.h): each particle's weight and compression past
// the floor, max(rho/rho0 - 1 - COARSE_FLOOR, 0) at x_pred, spread over the eight coarse nodes around it
// (cloud-in-cell), summed in fixed point by atomics. The buffer is cleared before.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "contract.h"
#include "coarse.glsl"

layout(std430, binding = 5) readonly buffer XPred { vec4 x_pred[]; };
layout(std430, binding = 6) readonly buffer Rho { float rho[]; };
layout(std430, binding = 7) buffer Sums { uint sums[]; };  // per node: filled, excess

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  float compression = clamp(rho[i] / sim.rho0 - 1.0 - COARSE_FLOOR, 0.0, COARSE_MAX_COMPRESSION);
  CoarseCorner c = coarse_corner(x_pred[i].xyz);
  for (int k = 0; k < 8; ++k) {
    float w;
    int node = coarse_node(c, k, w);
    atomicAdd(sums[2 * node], uint(w * COARSE_UNIT + 0.5));
    if (compression > 0.0) atomicAdd(sums[2 * node + 1], uint(w * compression * COARSE_UNIT + 0.5));
  }
}
