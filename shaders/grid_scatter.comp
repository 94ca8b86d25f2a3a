#version 450
// Grid build, 4/4: moves each particle's data to its sorted slot, so that the particles of a
// cell (and of neighbouring cells) are adjacent in memory. Within its cell a particle's slot is
// its rank by index among the cell's particles (listed by grid_order.comp): the same order on
// every run, so a run's sums, and its results, are the same bits each time.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(std430, binding = 0) readonly buffer Cell { uint cell[]; };
layout(std430, binding = 2) readonly buffer CellStart { uint cell_start[]; };
layout(std430, binding = 3) readonly buffer XIn { vec4 x_in[]; };
layout(std430, binding = 4) readonly buffer PayloadIn { vec4 payload_in[]; };
layout(std430, binding = 5) readonly buffer IdIn { uint id_in[]; };
layout(std430, binding = 6) writeonly buffer XOut { vec4 x_out[]; };
layout(std430, binding = 7) writeonly buffer PayloadOut { vec4 payload_out[]; };
layout(std430, binding = 8) writeonly buffer IdOut { uint id_out[]; };
layout(std430, binding = 9) readonly buffer Order { uint order[]; };

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  uint c = cell[i], dst = cell_start[c];
  for (uint k = cell_start[c], end = cell_start[c + 1]; k < end; ++k) dst += order[k] < i ? 1u : 0u;
  x_out[dst] = x_in[i];
  payload_out[dst] = payload_in[i];
  id_out[dst] = id_in[i];
}
