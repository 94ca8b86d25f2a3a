#version 450
// White water's frame (shaders/white_water.h): each living particle reads the fluid around it
// (the grid's 27 cells at the last build, as the reference's for_each_candidate; no wall
// images), becomes spray, foam or bubble by its density, moves as that kind does, stops at the
// walls and obstacles (as a fluid particle's prediction does), ages, and is written to the
// same slot of the other list, marked in `keep` if it still lives (white_water_compact.comp
// then packs the survivors in order). One thread a slot of the capacity: the living are the
// first min(count, capacity).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "white_water.glsl"
#include "grid_walk.glsl"

layout(binding = 1, rgba32f) uniform readonly imageBuffer x;
layout(binding = 2, rgba32f) uniform readonly imageBuffer v;
layout(std430, binding = 3) readonly buffer WhiteCountIn { uint white_count_in; };
layout(std430, binding = 4) readonly buffer WhiteXIn { vec4 white_x_in[]; };
layout(std430, binding = 5) readonly buffer WhiteVIn { vec4 white_v_in[]; };
layout(std430, binding = 6) writeonly buffer Keep { uint keep[]; };  // zeroed before
layout(std430, binding = 7) writeonly buffer WhiteXOut { vec4 white_x_out[]; };
layout(std430, binding = 8) writeonly buffer WhiteVOut { vec4 white_v_out[]; };
#define OBSTACLES_BINDING 9
#include "solids.glsl"

layout(constant_id = 100) const int WHITE_WATER_MAX_PARTICLES = 0;  // the scene's key (gpu/key_constants.hpp)

void main() {
  uint k = thread_index();
  if (k >= min(white_count_in, uint(WHITE_WATER_MAX_PARTICLES))) return;
  vec4 xl = white_x_in[k], vt = white_v_in[k];
  vec3 p = xl.xyz, u = vt.xyz;
  float density = 0.0;
  vec3 carried = vec3(0.0);
  ivec3 first = first_cell(p), last = last_cell(p);
  for (int z = first.z; z <= last.z; ++z)
    for (int y = first.y; y <= last.y; ++y)
      for (uint j = row_begin(first, y, z), end = row_end(last, y, z); j < end; ++j) {
        vec3 d = imageLoad(x, int(j)).xyz - p;
        float w = poly6(dot(d, d));  // the density, and the fluid's velocity interpolated with it
        density += w;
        carried += w * imageLoad(v, int(j)).xyz;
      }
  uint kind = white_water_kind(sim.mass * density / sim.rho0);
  if (density > 0.0) carried /= density;
  float dt = sim.elapsed;
  vec3 g = tank_gravity();
  if (kind == WHITE_SPRAY)
    u += dt * g;
  else if (kind == WHITE_FOAM)
    u = carried;
  else
    u += -WHITE_BUOYANCY * dt * g + WHITE_DRAG * (carried - u);
  float unused = 0.0;  // white water does no work
  vec3 to = p + dt * u, inside = project_out_of_solids(stop_at_solids(p, to, unused), unused);
  u = mix(u, vec3(0.0), notEqual(inside, to));  // stopped by a wall or an obstacle
  float life = xl.w - dt;
  if (life <= 0.0) return;
  uint slot = k;
  keep[k] = 1u;
  uint tag = (floatBitsToUint(vt.w) & ~((1u << WHITE_KIND_BITS) - 1u)) | kind;
  white_x_out[slot] = vec4(inside, life);
  white_v_out[slot] = vec4(u, uintBitsToFloat(tag));
}
