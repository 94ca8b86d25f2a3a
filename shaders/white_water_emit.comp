#version 450
// White water's births (shaders/white_water.h): each fluid particle's potentials from its
// neighbours and their images behind the walls (an image's velocity mirrored: fluid running
// into a wall meets its image head on), and from them how many it bears this frame: `births`,
// scanned, places them in the particles' order (white_water_birth.comp).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "white_water.glsl"

layout(binding = 1, rgba32f) uniform readonly imageBuffer x;
layout(binding = 2, rgba32f) uniform readonly imageBuffer v;
layout(std430, binding = 3) readonly buffer Id { uint id[]; };
layout(std430, binding = 4) writeonly buffer Births { uint births[]; };  // zeroed before
#define OBSTACLES_BINDING 9
#define NEIGHBOUR_BINDING 7
#define CREASES_BINDING 10
#define NEIGHBOUR_CAPACITY_ID 1
#include "neighbours.glsl"

// The scene's keys (gpu/key_constants.hpp).
layout(constant_id = 100) const float WHITE_WATER_EMISSION = 0.0;
layout(constant_id = 4) const float FLOW_SPEED = 4.4;  // Derived::flow_speed, m/s (after WALK_CELLS, neighbours.glsl)

void main() {
  uint i;
  if (!neighbour_pass_particle(i)) return;
  vec3 xi = imageLoad(x, int(i)).xyz, vi = imageLoad(v, int(i)).xyz;
  float unit = FLOW_SPEED;
  if (length(vi) / unit <= WHITE_SPEED_MIN) return;  // too slow to make any: most of a calm fluid skips the walk
  Mirrors mirrors = neighbour_mirrors(i, xi);
  float trapped = 0.0, weights = 0.0;
  vec3 towards = vec3(0.0);
  int image;
  FOR_EACH_NEIGHBOUR(i, xi, mirrors, j, image) {
    vec3 xj = imageLoad(x, int(j)).xyz, d = mirror(mirrors, image, j, xj) - xi;
    vec3 vij = vi - mirror_velocity(mirrors, image, imageLoad(v, int(j)).xyz);
    float w = position_weight(d), r = length(d), s = length(vij);
    weights += w;
    towards += w * d;
    trapped += r > 0.0 && s > 0.0 ? w * s * (1.0 + dot(vij, d) / (s * r)) : 0.0;
  }
  float surface = length(towards) / (weights * sim.h);
  float outward = surface > 0.0 ? dot(vi, -normalize(towards)) / unit : 0.0;
  births[i] = white_water_born(trapped / weights / unit, surface, outward, length(vi) / unit,
                               WHITE_WATER_EMISSION * sim.elapsed, id[i], sim.frame);
}
