#version 450
// XSPH viscosity v_i += c sum_j V_j (v_j - v_i) W_ij, and the vorticity
// omega_i = sum_j V_j (v_j - v_i) x grad W_ij, both from the same velocities (V_j = m/rho0).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(std430, binding = 0) readonly buffer CellStart { uint cell_start[]; };
layout(std430, binding = 1) readonly buffer X { vec4 x[]; };
layout(std430, binding = 2) readonly buffer V { vec4 v[]; };
layout(std430, binding = 3) writeonly buffer VOut { vec4 v_out[]; };
layout(std430, binding = 4) writeonly buffer Omega { vec4 omega[]; };

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  vec3 xi = x[i].xyz;
  vec3 vi = v[i].xyz;
  vec3 smooth_v = vec3(0.0);
  vec3 curl = vec3(0.0);
  FOR_EACH_NEIGHBOUR(xi, j) {
    vec3 d = xi - x[j].xyz;
    float r2 = dot(d, d);
    if (r2 >= sim.h * sim.h) continue;
    vec3 vij = v[j].xyz - vi;
    smooth_v += vij * poly6(r2);
    curl += cross(vij, spiky_grad(d, sqrt(r2)));
  }
  float volume = sim.mass / sim.rho0;
  v_out[i] = vec4(vi + (sim.xsph_c * volume) * smooth_v, 0.0);
  omega[i] = vec4(volume * curl, 0.0);
}
