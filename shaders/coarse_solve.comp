#version 450
// The coarse correction, 2 of 3 (contract.h), in one workgroup: grad^2 phi = the excess
// volume per volume at the fluid's nodes, phi = 0 at nodes without fluid (the free surface),
// no flux through the walls; COARSE_SWEEPS red-black Gauss-Seidel sweeps from the last
// step's phi (it changes little from step to step), then phi's gradient at each fluid node
// (central differences; 0 elsewhere). A Jacobi pass corrects a
// density mode by a gain that falls as (k spacing)^2, so the long modes that carry a
// column's weight stay compressed; here they are solved whole (docs/physics.md).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "contract.h"
#include "coarse.glsl"

// In: coarse_deposit.comp's sums. The first loop turns each node's into (fluid: 1 or 0,
// the right-hand side's float bits).
layout(std430, binding = 5) coherent buffer Sums { uint sums[]; };
layout(std430, binding = 6) coherent buffer Phi { float phi[]; };
layout(std430, binding = 7) writeonly buffer Grad { vec4 grad[]; };

bool fluid(int k) { return sums[2 * k] != 0u; }
float value(ivec3 p) { return phi[node_index(p)]; }  // 0 at nodes without fluid: never updated
ivec3 node_at(int k) { return ivec3(k % NODES_X, (k / NODES_X) % NODES_Y, k / (NODES_X * NODES_Y)); }

// Gauss-Seidel at one fluid node: phi = (its neighbours' phi - the right-hand side h^2) / their
// count; a neighbour past a wall is left out (no flux), one without fluid reads 0.
void relax(ivec3 p, float omega) {
  int k = node_index(p);
  if (!fluid(k)) return;
  float sum = 0.0;
  int sides = 0;
  for (int a = 0; a < 3; ++a)
    for (int dir = -1; dir <= 1; dir += 2) {
      ivec3 q = p;
      q[a] += dir;
      if (q[a] < 0 || q[a] >= nodes()[a]) continue;
      sum += value(q);
      ++sides;
    }
  if (sides > 0) phi[k] = mix(phi[k], (sum - uintBitsToFloat(sums[2 * k + 1])) / float(sides), omega);
}

void sync() {
  memoryBarrierBuffer();
  barrier();
}

void main() {
  int count = NODES_X * NODES_Y * NODES_Z, stride = int(gl_WorkGroupSize.x);
  float volume = sim.mass / sim.rho0, omega = coarse_overrelaxation();
  for (int k = int(gl_LocalInvocationID.x); k < count; k += stride) {
    bool filled = float(sums[2 * k]) / COARSE_UNIT * volume > COARSE_FILL * CELL * CELL * CELL;
    sums[2 * k + 1] = floatBitsToUint(float(sums[2 * k + 1]) / COARSE_UNIT * volume / CELL);
    sums[2 * k] = filled ? 1u : 0u;
    if (!filled) phi[k] = 0.0;
  }
  sync();
  for (int sweep = 0; sweep < COARSE_SWEEPS; ++sweep)
    for (int colour = 0; colour < 2; ++colour) {
      // A node of this colour a thread: the j-th of them is on row j / per_row, at x = 2 (j % per_row)
      // or one more, as the row's parity makes the colour.
      int per_row = (NODES_X + 1) / 2;
      for (int j = int(gl_LocalInvocationID.x); j < per_row * NODES_Y * NODES_Z; j += stride) {
        int row = j / per_row;
        ivec3 p = ivec3(0, row % NODES_Y, row / NODES_Y);
        p.x = 2 * (j % per_row) + (colour + p.y + p.z) % 2;
        if (p.x < NODES_X) relax(p, omega);
      }
      sync();
    }
  for (int k = int(gl_LocalInvocationID.x); k < count; k += stride) {
    vec3 g = vec3(0.0);
    if (fluid(k)) {
      ivec3 p = node_at(k);
      for (int a = 0; a < 3; ++a) {
        ivec3 lo = p, hi = p;
        lo[a] -= 1;
        hi[a] += 1;
        float below = lo[a] >= 0 ? value(lo) : phi[k], above = hi[a] < nodes()[a] ? value(hi) : phi[k];
        g[a] = (above - below) / (2.0 * CELL);
      }
    }
    grad[k] = vec4(g, 0.0);
  }
}
