#version 450
// The coarse correction, 2 of 5 (contract.h): each node's deposit becomes (its flags, the
// Poisson equation's right-hand side, the excess volume per volume of its cell, as float bits).
// A node is fluid where its deposit fills more than COARSE_FILL of its reach's open part, or
// where a solid fills all but COARSE_FILL of it (fluid at rest); phi is 0 at the others (the
// free surface and the air, beside a solid too) and stays 0, as no sweep updates them. Past a
// wall above the node that it borders is air where none of the particles nearest it touches
// the wall (COARSE_WORDS). Each node adds itself to the totals the sweeps read (COARSE_TOTALS).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "contract.h"
#include "coarse.glsl"

layout(std430, binding = 5) buffer Sums { uint sums[]; };
layout(std430, binding = 6) writeonly buffer Phi { float phi[]; };
layout(std430, binding = 7) readonly buffer Open { float open[]; };  // Derived::Coarse::open

// The totals (contract.h, COARSE_TOTALS) gathered in the workgroup first, so that a grid of
// thousands of nodes adds to each global word once a workgroup, not once a node.
shared uint group_totals[COARSE_TOTALS];

// This node's flags; its share of the totals added to the workgroup's.
void prepare_node(int k) {
  float volume = sim.mass / sim.rho0;
  float cell_volume = CELL_X * CELL_Y * CELL_Z;
  int first = COARSE_WORDS * k;
  bool deposited = float(sums[first]) / COARSE_UNIT * volume > COARSE_FILL * open[k] * cell_volume;
  bool filled = deposited || open[k] < COARSE_FILL;
  uint excess = sums[first + 1];
  sums[first + 1] = floatBitsToUint(float(excess) / COARSE_UNIT * volume / cell_volume);
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
  if (flags != COARSE_FLUID) atomicAdd(group_totals[COARSE_TOTAL_AIR], 1u);  // air, or air past a wall
  if (!filled) return;
  atomicAdd(group_totals[COARSE_TOTAL_FLUID], 1u);
  if (atomicAdd(group_totals[COARSE_TOTAL_EXCESS], excess) > 0xffffffffu - excess)  // the low word wraps
    atomicAdd(group_totals[COARSE_TOTAL_EXCESS + 1], 1u);
}

void main() {
  int k = int(thread_index());
  if (gl_LocalInvocationIndex < COARSE_TOTALS) group_totals[gl_LocalInvocationIndex] = 0u;
  barrier();
  if (k < NODES_X * NODES_Y * NODES_Z) prepare_node(k);
  barrier();
  if (gl_LocalInvocationIndex != 0u) return;
  int totals = COARSE_WORDS * NODES_X * NODES_Y * NODES_Z;
  atomicAdd(sums[totals + COARSE_TOTAL_FLUID], group_totals[COARSE_TOTAL_FLUID]);
  atomicAdd(sums[totals + COARSE_TOTAL_AIR], group_totals[COARSE_TOTAL_AIR]);
  uint low = group_totals[COARSE_TOTAL_EXCESS];
  uint carries = group_totals[COARSE_TOTAL_EXCESS + 1] + (atomicAdd(sums[totals + COARSE_TOTAL_EXCESS], low) > 0xffffffffu - low ? 1u : 0u);
  atomicAdd(sums[totals + COARSE_TOTAL_EXCESS + 1], carries);
}
