#version 450
// White water's survivors packed in their order (shaders/white_water.h): `keep`, scanned, gives
// each survivor of white_water_advect.comp its slot, so the list is the same on every run; the
// last entry, the survivors' count, becomes the list's count.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(std430, binding = 1) readonly buffer Slots { uint slots[]; };  // keep, exclusive-scanned
layout(std430, binding = 2) readonly buffer WhiteXIn { vec4 white_x_in[]; };
layout(std430, binding = 3) readonly buffer WhiteVIn { vec4 white_v_in[]; };
layout(std430, binding = 4) writeonly buffer WhiteCount { uint white_count[]; };
layout(std430, binding = 5) writeonly buffer WhiteXOut { vec4 white_x_out[]; };
layout(std430, binding = 6) writeonly buffer WhiteVOut { vec4 white_v_out[]; };

layout(constant_id = 100) const int WHITE_WATER_MAX_PARTICLES = 0;  // the scene's key (gpu/key_constants.hpp)

void main() {
  uint k = thread_index(), capacity = uint(WHITE_WATER_MAX_PARTICLES);
  if (k == capacity) white_count[0] = slots[capacity];
  if (k >= capacity || slots[k + 1] == slots[k]) return;
  white_x_out[slots[k]] = white_x_in[k];
  white_v_out[slots[k]] = white_v_in[k];
}
