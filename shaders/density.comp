#version 450
// rho_i = sum_j m W_poly6(x_i - x_j), self included, and the neighbours' images behind the walls.
// The first pass after a grid build at x: it builds the neighbour lists (neighbours.glsl).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(std430, binding = 0) readonly buffer CellStart { uint cell_start[]; };
layout(std430, binding = 1) readonly buffer X { vec4 x[]; };
layout(std430, binding = 2) writeonly buffer Rho { float rho[]; };
#define NEIGHBOUR_BINDING 3
#define NEIGHBOUR_CAPACITY_ID 1
#define NEIGHBOUR_BUILDER
#define NEIGHBOUR_X x
#include "neighbours.glsl"

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  vec3 xi = x[i].xyz;
  build_neighbour_list(i, xi);
  WallImages walls = walls_near(xi);
  float sum = 0.0;
  FOR_EACH_NEIGHBOUR(i, xi, j) {
    vec3 xj = x[j].xyz, d = xi - xj;
    sum += poly6(dot(d, d));
    for (int k = walls.axes; k != 0; k = next_image(walls, k)) {
      d = xi - mirror(walls, k, xj);
      sum += poly6(dot(d, d));
    }
  }
  rho[i] = sim.mass * sum;
}
