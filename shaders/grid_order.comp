#version 450
// Grid build, 3/4: each cell's particles listed at its slots, in the order the count's atomics
// ranked them, so that the scatter can rank each particle by its index within the cell instead:
// the same sort on every run, whatever order the atomics took.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
layout(std430, binding = 0) readonly buffer Cell { uint cell[]; };
layout(std430, binding = 1) readonly buffer Rank { uint rank[]; };
layout(std430, binding = 2) readonly buffer CellStart { uint cell_start[]; };
layout(std430, binding = 3) writeonly buffer Order { uint order[]; };
void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  order[cell_start[cell[i]] + rank[i]] = i;
}
