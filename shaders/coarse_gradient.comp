#version 450
// The coarse correction, 4 of 5 (contract.h): phi's gradient at each fluid node by central
// differences (one-sided against a wall, where phi's flux is 0; against air past a wall, 0
// there); 0 at the other nodes.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "contract.h"
#include "coarse.glsl"

layout(std430, binding = 5) readonly buffer Sums { uint sums[]; };  // coarse_prepare.comp's
layout(std430, binding = 6) readonly buffer Phi { float phi[]; };
layout(std430, binding = 7) writeonly buffer Grad { vec4 grad[]; };

void main() {
  int k = int(thread_index());
  if (k >= NODES_X * NODES_Y * NODES_Z) return;
  vec3 g = vec3(0.0);
  uint flags = sums[COARSE_WORDS * k];
  if (flags != 0u) {
    ivec3 p = node_at(k);
    for (int a = 0; a < 3; ++a) {
      ivec3 lo = p, hi = p;
      lo[a] -= 1;
      hi[a] += 1;
      float wall_lo = (flags & (COARSE_AIR_PAST << (2 * a))) != 0u ? 0.0 : phi[k];
      float wall_hi = (flags & (COARSE_AIR_PAST << (2 * a + 1))) != 0u ? 0.0 : phi[k];
      float below = lo[a] >= 0 ? phi[node_index(lo)] : wall_lo, above = hi[a] < nodes()[a] ? phi[node_index(hi)] : wall_hi;
      g[a] = (above - below) / (2.0 * cell()[a]);
    }
  }
  grad[k] = vec4(g, 0.0);
}
