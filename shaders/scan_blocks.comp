#version 450
// Exclusive prefix sum, in place, of each block of 1024 values; the block's total goes
// to sums[block]. Larger arrays scan the sums recursively (host/gpu_grid.cpp).
layout(local_size_x = 256) in;

layout(std430, binding = 0) buffer Data { uint data[]; };
layout(std430, binding = 1) writeonly buffer Sums { uint sums[]; };
layout(push_constant) uniform Push { uint n; } push;

const uint PER_THREAD = 4;
shared uint totals[256];

void main() {
  uint t = gl_LocalInvocationID.x;
  uint base = gl_WorkGroupID.x * 256 * PER_THREAD + t * PER_THREAD;
  uint v[PER_THREAD];
  uint sum = 0;
  for (uint k = 0; k < PER_THREAD; ++k) {
    v[k] = base + k < push.n ? data[base + k] : 0u;
    sum += v[k];
  }
  // Inclusive Hillis-Steele scan of the per-thread sums.
  totals[t] = sum;
  barrier();
  for (uint step = 1; step < 256; step <<= 1) {
    uint add = t >= step ? totals[t - step] : 0u;
    barrier();
    totals[t] += add;
    barrier();
  }
  uint running = totals[t] - sum;  // exclusive prefix of this thread
  for (uint k = 0; k < PER_THREAD; ++k) {
    if (base + k < push.n) data[base + k] = running;
    running += v[k];
  }
  if (t == 255) sums[gl_WorkGroupID.x] = totals[255];
}
