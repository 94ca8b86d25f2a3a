#version 450
// Exclusive prefix sum, in place, of push.blocks consecutive blocks of 1024 values per
// workgroup, carried from block to block; the group's total goes to sums[group]. A grid
// of up to 32 blocks scans in one group (host/gpu/gpu_grid.cpp); a larger one scans a block
// per group, then the sums recursively, then adds them back (scan_add.comp).
// Shaped for a CPU device, where the scan was most of the grid build: every storage access
// runs lane by lane, so each thread moves its 16 values as four uvec4; a barrier switches
// all of a workgroup's 8-lane slices, so 64 threads and a raked scan of their sums take
// four barriers a block, where a 256-thread Hillis-Steele scan takes 16.
layout(local_size_x = 64) in;

layout(std430, binding = 0) buffer Data { uvec4 data[]; };  // padded to whole blocks
layout(std430, binding = 1) writeonly buffer Sums { uint sums[]; };
layout(push_constant) uniform Push {
  uint n;       // values, not vectors
  uint blocks;  // per workgroup
} push;

const uint THREADS = 64, VECTORS = 4, RAKES = 8, PER_RAKE = THREADS / RAKES;
shared uint totals[THREADS];
shared uint rake_totals[RAKES + 1];  // the rakes' exclusive prefixes, then the block's total

void main() {
  uint t = gl_LocalInvocationID.x;
  uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  if (group * push.blocks * THREADS * VECTORS * 4 >= push.n) return;  // past the last block (groups folded into y)
  uint carry = 0;  // the group's blocks before this one
  for (uint b = 0; b < push.blocks; ++b) {
    uint first = ((group * push.blocks + b) * THREADS + t) * VECTORS;
    uvec4 v[VECTORS];
    uint sum = 0;
    for (uint k = 0; k < VECTORS; ++k) {
      // The padding past n holds anything (the block sums' levels are not cleared).
      uvec4 index = 4 * (first + k) + uvec4(0, 1, 2, 3);
      v[k] = mix(uvec4(0), data[first + k], lessThan(index, uvec4(push.n)));
      sum += v[k].x + v[k].y + v[k].z + v[k].w;
    }
    totals[t] = sum;
    barrier();
    if (t < RAKES) {  // each rake scans its threads' sums, exclusive, in place
      uint running = 0;
      for (uint k = 0; k < PER_RAKE; ++k) {
        uint s = totals[t * PER_RAKE + k];
        totals[t * PER_RAKE + k] = running;
        running += s;
      }
      rake_totals[t] = running;
    }
    barrier();
    if (t == 0) {  // the rakes' totals, exclusive, and the block's total after them
      uint running = 0;
      for (uint k = 0; k < RAKES; ++k) {
        uint s = rake_totals[k];
        rake_totals[k] = running;
        running += s;
      }
      rake_totals[RAKES] = running;
    }
    barrier();
    uint running = carry + totals[t] + rake_totals[t / PER_RAKE];  // exclusive prefix of this thread
    for (uint k = 0; k < VECTORS; ++k) {
      uvec4 e = uvec4(0, v[k].x, v[k].x + v[k].y, v[k].x + v[k].y + v[k].z);
      data[first + k] = running + e;
      running += e.w + v[k].w;
    }
    carry += rake_totals[RAKES];
    barrier();  // every thread has read this block's totals before the next block writes them
  }
  if (t == 0) sums[group] = carry;
}
