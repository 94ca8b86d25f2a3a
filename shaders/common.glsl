// Shared by every particle pass: the simulation constants (declared in sim_constants.h), the
// SPH kernels (mirrors host/sim/kernels.hpp) and the grid lookup.

#include "sim_constants.h"
#define SIM_FIELD(type, name) type name;
layout(push_constant) uniform Sim { SIM_CONSTANTS(SIM_FIELD) } sim;
#undef SIM_FIELD

// Dispatches larger than the group-count limit fold into y (CommandList::dispatch).
uint thread_index() {
  return gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
}

// poly6: W(r) = 315/(64 pi h^3) (1 - r^2/h^2)^3 for r < h, in q = r/h so that no power of h
// leaves float's range (kernels::poly6_scale says why).
float poly6(float r2) {
  float d = 1.0 - r2 / (sim.h * sim.h);
  return d > 0.0 ? sim.poly6_scale * d * d * d : 0.0;
}

// Gradient of the spiky kernel with respect to x_i, for d = x_i - x_j and r = |d|:
// -45/(pi h^4) (1 - r/h)^2 d/r for 0 < r < h; its shape alone, without the 1/h^4, where only
// a direction is wanted (kernels::spiky_grad_shape).
vec3 spiky_grad_shape(vec3 d, float r) {
  if (r <= 0.0 || r >= sim.h) return vec3(0.0);
  float s = 1.0 - r / sim.h;
  return (-s * s / r) * d;
}
vec3 spiky_grad(vec3 d, float r) { return sim.spiky_grad_scale * spiky_grad_shape(d, r); }

// The weight of a neighbourhood mean, 1 - (r/h)^8 (kernels::smoothing_weight says why).
float smoothing_weight(vec3 d) {
  float t = dot(d, d) / (sim.h * sim.h), t2 = t * t;
  return max(1.0 - t2 * t2, 0.0);
}

// The weight of the smoothed positions' mean, 1 - (r/h)^3 (kernels::position_weight says why).
float position_weight(vec3 d) {
  float t = length(d) / sim.h;
  return max(1.0 - t * t * t, 0.0);
}

// A neighbour list's entry (neighbours.glsl): particle j's image k (0: j itself) in one
// word, k in the top four bits (solids.glsl). 2^28 particles fit; a run holds fewer, as a
// storage buffer's range (a 32-bit size) ends there for the vec4 arrays (check_device_memory).
const uint IMAGE_SHIFT = 28u, IMAGE_INDEX_MASK = (1u << IMAGE_SHIFT) - 1u;
uint image_entry(uint j, int k) { return j | (uint(k) << IMAGE_SHIFT); }
// A list's count with this bit: the particle had an obstacle within h, and the near readers serve it.
const uint NEAR_FLAG = 1u << 31;

ivec3 cell_of(vec3 x) {
  // Clamp in float first (a far-away position must not overflow the int), then in int:
  // a NaN converts to an undefined int, and the int clamp keeps even that inside the
  // grid, so a diverged particle never indexes out of bounds (the watch reports it).
  vec3 c = clamp(floor((x - sim.domain_min) / sim.h), vec3(0.0), vec3(sim.grid - 1));
  return clamp(ivec3(c), ivec3(0), sim.grid - 1);
}

uint cell_id(ivec3 c) { return uint((c.z * sim.grid.y + c.y) * sim.grid.x + c.x); }

vec3 project_to_walls(vec3 x) { return clamp(x, sim.wall_min, sim.wall_max); }
