#version 450
// The coarse correction, 3 of 5 (contract.h): red-black sweeps of over-relaxed Gauss-Seidel
// for grad^2 phi = the excess volume per volume at the fluid nodes (less its mean where no node
// has air: COARSE_TOTALS), COARSE_SWEEPS of them from the last step's phi (it changes little
// from step to step). A Jacobi pass corrects a density mode by a gain that falls as
// (k spacing)^2, so the long modes that carry a column's weight stay compressed; here they are
// solved whole (docs/physics.md).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "contract.h"
#include "coarse.glsl"

// A small grid is solved in one dispatch: one workgroup holds the whole of phi in shared memory
// (SHARED_NODES, the grid's node count) through all COARSE_SWEEPS sweeps, a workgroup barrier
// between half sweeps. A large grid (SHARED_NODES 0) takes a dispatch per half sweep, phi in
// the buffer, across as many workgroups as it has nodes of a colour (GpuSolver's
// coarse_sweep_group says which, and what one workgroup saves).
layout(constant_id = 7) const int FIRST_COLOUR = 0;  // (x + y + z) % 2 of the nodes updated first
layout(constant_id = 8) const int SHARED_NODES = 0;
const bool WHOLE = SHARED_NODES > 0;
layout(std430, binding = 5) readonly buffer Sums { uint sums[]; };  // coarse_prepare.comp's
layout(std430, binding = 6) buffer Phi { float phi[]; };
shared float phi_shared[WHOLE ? SHARED_NODES : 1];

float phi_at(int k) { return WHOLE ? phi_shared[k] : phi[k]; }

// phi at the j-th node of a colour moves toward the value that zeroes its Laplacian's residual,
// each neighbour weighed by 1 / (its axis's cell)^2; a neighbour past a wall is left out (no
// flux) or, past a lid the water does not touch (COARSE_AIR_PAST), reads 0 as one without fluid. The
// j-th node is on row j / per_row, at x = 2 (j % per_row) or one more, as the row's parity
// makes the colour.
void sweep_node(int j, int colour, float overrelaxation, float mean) {
  int per_row = (NODES_X + 1) / 2, row = j / per_row;
  ivec3 p = ivec3(0, row % NODES_Y, row / NODES_Y);
  p.x = 2 * (j % per_row) + (colour + p.y + p.z) % 2;
  if (p.x >= NODES_X) return;
  int k = node_index(p);
  uint flags = sums[COARSE_WORDS * k];
  if (flags == 0u) return;  // not fluid
  float sum = 0.0, weights = 0.0;
  for (int a = 0; a < 3; ++a) {
    float w = 1.0 / (cell()[a] * cell()[a]);
    for (int side = 0; side < 2; ++side) {
      ivec3 q = p;
      q[a] += 2 * side - 1;
      bool past = q[a] < 0 || q[a] >= nodes()[a];
      if (past && (flags & (COARSE_AIR_PAST << (2 * a + side))) == 0u) continue;
      if (!past) sum += w * phi_at(node_index(q));
      weights += w;
    }
  }
  if (weights == 0.0) return;
  float relaxed = mix(phi_at(k), (sum - (uintBitsToFloat(sums[COARSE_WORDS * k + 1]) - mean)) / weights, overrelaxation);
  if (WHOLE) phi_shared[k] = relaxed;
  else phi[k] = relaxed;
}

// The fluid nodes' mean right-hand side where no node has air (contract.h, COARSE_TOTALS), else 0.
float mean_source() {
  int totals = COARSE_WORDS * NODES_X * NODES_Y * NODES_Z;
  uint fluid = sums[totals + COARSE_TOTAL_FLUID];
  if (fluid == 0u || sums[totals + COARSE_TOTAL_AIR] != 0u) return 0.0;
  float excess = float(sums[totals + COARSE_TOTAL_EXCESS + 1]) * 4294967296.0 + float(sums[totals + COARSE_TOTAL_EXCESS]);
  return excess / float(fluid) / COARSE_UNIT * (sim.mass / sim.rho0) / (CELL_X * CELL_Y * CELL_Z);
}

void main() {
  int per_colour = (NODES_X + 1) / 2 * NODES_Y * NODES_Z;  // Derived::Coarse::per_colour
  int first = int(thread_index());
  int stride = int(gl_NumWorkGroups.x * gl_NumWorkGroups.y * gl_WorkGroupSize.x);
  float overrelaxation = coarse_overrelaxation(), mean = mean_source();
  if (WHOLE) {
    for (int k = first; k < SHARED_NODES; k += stride) phi_shared[k] = phi[k];
    barrier();
  }
  for (int sweep = 0; sweep < (WHOLE ? COARSE_SWEEPS : 1); ++sweep)
    for (int c = 0; c < (WHOLE ? 2 : 1); ++c) {
      for (int j = first; j < per_colour; j += stride) sweep_node(j, (FIRST_COLOUR + c) % 2, overrelaxation, mean);
      if (WHOLE) barrier();
    }
  if (WHOLE)
    for (int k = first; k < SHARED_NODES; k += stride) phi[k] = phi_shared[k];
}
