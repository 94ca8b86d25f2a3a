#version 450
// Vorticity confinement: f_i = eps (N x omega_i), N = eta/|eta|, eta = sum_j V_j |omega_j| grad W_ij;
// applied as v_i += f_i dt.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(std430, binding = 0) readonly buffer CellStart { uint cell_start[]; };
layout(std430, binding = 1) readonly buffer X { vec4 x[]; };
layout(std430, binding = 2) readonly buffer Omega { vec4 omega[]; };
layout(std430, binding = 3) buffer V { vec4 v[]; };
#define NEIGHBOUR_BINDING 4
#define NEIGHBOUR_CAPACITY_ID 1
#include "neighbours.glsl"

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  vec3 xi = x[i].xyz;
  vec3 eta = vec3(0.0);
  FOR_EACH_NEIGHBOUR(i, xi, j) {
    vec3 d = xi - x[j].xyz;
    if (dot(d, d) >= sim.h * sim.h) continue;
    eta += length(omega[j].xyz) * spiky_grad(d, length(d));
  }
  float len = length(eta);
  if (len > 1e-9) v[i].xyz += (sim.vorticity_eps * sim.dt / len) * cross(eta, omega[i].xyz);
}
