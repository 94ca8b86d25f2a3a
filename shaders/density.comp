#version 450
// rho_i = sum_j m W_poly6(x_i - x_j), self included, plus the walls' share.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(std430, binding = 0) readonly buffer CellStart { uint cell_start[]; };
layout(std430, binding = 1) readonly buffer X { vec4 x[]; };
layout(std430, binding = 2) writeonly buffer Rho { float rho[]; };

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  vec3 xi = x[i].xyz;
  float sum = 0.0;
  FOR_EACH_NEIGHBOUR(xi, j) {
    vec3 d = xi - x[j].xyz;
    sum += poly6(dot(d, d));
  }
  vec3 wall_grad;
  rho[i] = sim.mass * sum + wall_density(xi, wall_grad);
}
