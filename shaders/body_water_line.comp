#version 450
// Each body's water line (host/sim/solids/coupling.hpp, add_buoyancy): the height along up (the
// host's, at BODY_UP_WORD) of the highest particle within a spacing of its grown surface (where
// particle centres stop) and no higher than its top (the host's BODY_TOP_WORD), as an ordered
// float by atomicMax: the largest whatever the order.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(std430, binding = 0) readonly buffer XPred { vec4 x_pred[]; };
#define OBSTACLES_BINDING 1
#define BODY_PUSH_BINDING 2
#include "solids.glsl"

// A float's bits as a uint that orders as the floats do: the sign bit set on the positives, every
// bit flipped on the negatives.
uint ordered(float f) {
  uint u = floatBitsToUint(f);
  return (u & 0x80000000u) != 0u ? ~u : u | 0x80000000u;
}

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  vec3 x = x_pred[i].xyz;
  float margin = obstacle_data[0].y, spacing = 2.0 * margin;  // the margin is half a spacing
  for (int k = 0; k < OBSTACLE_COUNT; ++k) {
    int b = body_of(k);
    if (b < 0) continue;
    int words = b * BODY_PUSH_WORDS + BODY_UP_WORD;
    vec3 normal, up = vec3(uintBitsToFloat(body_push[words]), uintBitsToFloat(body_push[words + 1]), uintBitsToFloat(body_push[words + 2]));
    float height = dot(x, up);
    if (height <= uintBitsToFloat(body_push[b * BODY_PUSH_WORDS + BODY_TOP_WORD]) && obstacle_surface(k, x, normal) - margin < spacing)
      atomicMax(body_push[b * BODY_PUSH_WORDS + BODY_LINE_WORD], ordered(height));
  }
}
