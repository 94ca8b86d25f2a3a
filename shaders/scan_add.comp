#version 450
// Adds each block's scanned offset to the values of that block (second half of a
// recursive scan): 16 values, four uvec4, per thread (scan_blocks.comp says why).
layout(local_size_x = 64) in;

layout(std430, binding = 0) buffer Data { uvec4 data[]; };  // padded to whole blocks
layout(std430, binding = 1) readonly buffer Sums { uint sums[]; };
layout(push_constant) uniform Push { uint n; } push;  // values, not vectors

const uint VECTORS = 4, THREADS_PER_BLOCK = 1024 / (4 * VECTORS);

void main() {
  uint t = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  if (t * VECTORS * 4 >= push.n) return;  // past the values (groups folded into y)
  uint add = sums[t / THREADS_PER_BLOCK];
  for (uint k = 0; k < VECTORS; ++k) data[t * VECTORS + k] += add;
}
