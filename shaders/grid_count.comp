#version 450
// Grid build, 1/4: each particle's cell, and a rank among the particles of that cell in the
// order the atomics take (the scatter ranks by index instead).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(std430, binding = 0) readonly buffer X { vec4 x[]; };
layout(std430, binding = 1) writeonly buffer Cell { uint cell[]; };
layout(std430, binding = 2) writeonly buffer Rank { uint rank[]; };
layout(std430, binding = 3) buffer Count { uint count[]; };  // zeroed before

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  uint c = cell_id(cell_of(x[i].xyz));
  cell[i] = c;
  rank[i] = atomicAdd(count[c], 1u);
}
