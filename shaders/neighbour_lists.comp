#version 450
// The neighbour lists (DESIGN.md steps 1 and 5): after each grid build, every particle
// walks the 27 cells around it once and lists the particles within h (itself included);
// the passes that follow read the list (neighbours.glsl) instead of walking the ~8x as
// many candidates again. Its own pass, so that every reader gathers through texel
// buffers, which a pass cannot use for what it wrote itself.
// A list holds at most NEIGHBOUR_CAPACITY entries; the count goes on past it (squeezed
// fluid), and such a particle is never cut short: the readers walk its cells instead, so
// a full list costs time, not neighbours. A capacity of 0 means no lists at all (they
// would not fit the device, host/memory_estimate.hpp): every count reads "overflowed".
// Layout, for the readers' coalesced uvec4 fetches: entries go in groups of four, group g
// of particle i at texel g * count + i (neighbour-major: adjacent invocations read
// adjacent texels), entry k in group k / 4, lane k % 4.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "grid_walk.glsl"

layout(binding = 1) uniform samplerBuffer x;  // the positions the lists are built at
layout(std430, binding = 2) writeonly buffer NeighbourCount { uint neighbour_count[]; };
layout(std430, binding = 3) writeonly buffer NeighbourList { uint neighbour_list[]; };
layout(constant_id = 1) const uint NEIGHBOUR_CAPACITY = 64;  // Derived::neighbour_capacity (groups rounded up: list_words)

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  if (NEIGHBOUR_CAPACITY == 0u) {
    neighbour_count[i] = 1u;
    return;
  }
  vec3 xi = texelFetch(x, int(i)).xyz;
  uint listed = 0u;
  FOR_EACH_CANDIDATE(xi, j) {
    vec3 d = xi - texelFetch(x, int(j)).xyz;
    if (dot(d, d) >= sim.h * sim.h) continue;
    if (listed < NEIGHBOUR_CAPACITY) neighbour_list[4u * ((listed >> 2) * sim.count + i) + (listed & 3u)] = j;
    ++listed;
  }
  neighbour_count[i] = listed;
}
