#version 450
// Drains, 1 of 2 (sim/flow.hpp): each particle kept (1) or inside a drain box (0), strictly, as
// Drain::contains; the entry past the last stays 0 for the scan's total.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(constant_id = 1) const int DRAINS = 1;  // the scene's drains
layout(std430, binding = 1) readonly buffer X { vec4 x[]; };
layout(std430, binding = 2) readonly buffer Drains { vec4 drains[]; };  // (min, 0) (max, 0) each
layout(std430, binding = 3) writeonly buffer Keep { uint keep[]; };

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  bool inside = false;
  for (int k = 0; k < DRAINS; ++k)
    inside = inside || (all(greaterThan(x[i].xyz, drains[2 * k].xyz)) && all(lessThan(x[i].xyz, drains[2 * k + 1].xyz)));
  keep[i] = inside ? 0u : 1u;
}
