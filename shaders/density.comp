#version 450
// rho_i = sum_j m W_poly6(x_i - x_j), self included, and the neighbours' images behind the walls.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(binding = 1, rgba32f) uniform readonly imageBuffer x;
layout(std430, binding = 2) writeonly buffer Rho { float rho[]; };
#define OBSTACLES_BINDING 5
#define NEIGHBOUR_BINDING 3
#define CREASES_BINDING 6
#define NEIGHBOUR_CAPACITY_ID 1
#include "neighbours.glsl"

void main() {
  uint i;
  if (!neighbour_pass_particle(i)) return;
  vec3 xi = imageLoad(x, int(i)).xyz;
  Mirrors mirrors = neighbour_mirrors(i, xi);
  float sum = 0.0;
  int image;
  FOR_EACH_NEIGHBOUR(i, xi, mirrors, j, image) {
    vec3 d = xi - mirror(mirrors, image, j, imageLoad(x, int(j)).xyz);
    sum += poly6(dot(d, d));
  }
  rho[i] = sim.mass * sum;
}
