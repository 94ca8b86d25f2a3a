#version 450
// White water's births, in the particles' order (shaders/white_water.h): fluid particle i's
// births (white_water_emit.comp's count, scanned) go after the living at their scanned slots,
// each a spacing's cube around it at its velocity, as foam until the next advect reads the
// fluid around it: the same list on every run. Past the capacity, births are dropped; the
// count still counts them (readers take the smaller), written to its second word (the first
// is this pass's base), which the host copies over the first.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "white_water.glsl"

layout(binding = 1, rgba32f) uniform readonly imageBuffer x;
layout(binding = 2, rgba32f) uniform readonly imageBuffer v;
layout(std430, binding = 3) readonly buffer Id { uint id[]; };
layout(std430, binding = 4) readonly buffer Slots { uint slots[]; };  // births, exclusive-scanned
layout(std430, binding = 5) buffer WhiteCount { uint white_count[]; };  // [0] the living, [1] after the births
layout(std430, binding = 6) writeonly buffer WhiteX { vec4 white_x[]; };  // (x, life)
layout(std430, binding = 7) writeonly buffer WhiteV { vec4 white_v[]; };  // (v, tag's bits)

// The scene's keys (gpu/key_constants.hpp).
layout(constant_id = 100) const float WHITE_WATER_LIFETIME = 0.0;
layout(constant_id = 101) const int WHITE_WATER_MAX_PARTICLES = 0;
layout(constant_id = 1) const float SPACING = 0.02;

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  uint base = white_count[0];
  if (i == 0u) white_count[1] = base + slots[sim.count];
  vec3 xi = imageLoad(x, int(i)).xyz, vi = imageLoad(v, int(i)).xyz;
  uint emitter = id[i];
  for (uint b = 0u, k = base + slots[i]; k < base + slots[i + 1u] && k < uint(WHITE_WATER_MAX_PARTICLES); ++b, ++k) {
    uint seed = white_seed(emitter, b, sim.frame);
    vec3 offset = vec3(white_unit(seed, 1u), white_unit(seed, 2u), white_unit(seed, 3u)) - 0.5;
    white_x[k] = vec4(xi + SPACING * offset, WHITE_WATER_LIFETIME * (0.5 + white_unit(seed, 4u)));
    white_v[k] = vec4(vi, uintBitsToFloat(((emitter & WHITE_TAG_ID_MASK) * WHITE_MOST_BORN + b) << WHITE_KIND_BITS | WHITE_FOAM));
  }
}
