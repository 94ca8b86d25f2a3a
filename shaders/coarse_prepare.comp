#version 450
// The coarse correction, 2 of 5 (contract.h): each node's deposit becomes (fluid: 1 or 0, the
// Poisson equation's right-hand side, the excess volume per volume of its cell, as float bits).
// A node is fluid where its deposit fills more than COARSE_FILL of its reach's open part, or
// where a solid fills all but COARSE_FILL of it (fluid at rest); phi is 0 at the others (the
// free surface and the air, beside a solid too) and stays 0, as no sweep updates them.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "contract.h"
#include "coarse.glsl"

layout(std430, binding = 5) buffer Sums { uint sums[]; };
layout(std430, binding = 6) writeonly buffer Phi { float phi[]; };
layout(std430, binding = 7) readonly buffer Open { float open[]; };  // Derived::Coarse::open

void main() {
  int k = int(thread_index());
  if (k >= NODES_X * NODES_Y * NODES_Z) return;
  float volume = sim.mass / sim.rho0;
  float cell_volume = CELL_X * CELL_Y * CELL_Z;
  bool filled = float(sums[2 * k]) / COARSE_UNIT * volume > COARSE_FILL * open[k] * cell_volume || open[k] < COARSE_FILL;
  sums[2 * k + 1] = floatBitsToUint(float(sums[2 * k + 1]) / COARSE_UNIT * volume / cell_volume);
  sums[2 * k] = filled ? 1u : 0u;
  if (!filled) phi[k] = 0.0;
}
