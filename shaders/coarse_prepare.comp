#version 450
// The coarse correction, 2 of 5 (contract.h): each node's deposit becomes (its flags, the
// Poisson equation's right-hand side, the excess volume per volume of its cell, as float bits).
// A node is fluid where its deposit fills more than COARSE_FILL of its reach's open part, or
// where a solid fills all but COARSE_FILL of it (fluid at rest); phi is 0 at the others (the
// free surface and the air, beside a solid too) and stays 0, as no sweep updates them. Past a
// wall above the node that it borders is air where none of the particles nearest it touches
// the wall (COARSE_WORDS).
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
  int first = COARSE_WORDS * k;
  bool deposited = float(sums[first]) / COARSE_UNIT * volume > COARSE_FILL * open[k] * cell_volume;
  bool filled = deposited || open[k] < COARSE_FILL;
  sums[first + 1] = floatBitsToUint(float(sums[first + 1]) / COARSE_UNIT * volume / cell_volume);
  uint flags = filled ? COARSE_FLUID : 0u;
  if (deposited && open[k] > 1.0 - COARSE_FILL) {
    ivec3 p = node_at(k);
    uint touched = sums[first + 2];
    float g = length(sim.gravity);
    vec3 up = g > 0.0 ? -sim.gravity / g : vec3(0.0);
    for (int a = 0; a < 3; ++a) {
      if (p[a] == 0 && -up[a] > COARSE_UP && (touched & (1u << (2 * a))) == 0u) flags |= COARSE_AIR_PAST << (2 * a);
      if (p[a] == nodes()[a] - 1 && up[a] > COARSE_UP && (touched & (2u << (2 * a))) == 0u)
        flags |= COARSE_AIR_PAST << (2 * a + 1);
    }
  }
  sums[first] = flags;
  if (!filled) phi[k] = 0.0;
}
