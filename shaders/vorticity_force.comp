#version 450
// Vorticity confinement: f_i = eps (N x w_i), N = eta/|eta|, eta = sum_j V_j |w_j| (w: the curl) grad W_ij;
// applied as v_i += f_i dt.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(constant_id = 100) const float SOLVER_VORTICITY = 0.0;  // eps, m/s (gpu/key_constants.hpp)

layout(binding = 1, rgba32f) uniform readonly imageBuffer x;
layout(binding = 2, rgba32f) uniform readonly imageBuffer curl;
layout(std430, binding = 3) buffer V { vec4 v[]; };
#define OBSTACLES_BINDING 6
#define NEIGHBOUR_BINDING 4
#define CREASES_BINDING 7
#define NEIGHBOUR_CAPACITY_ID 1
#include "neighbours.glsl"

void main() {
  uint i;
  if (!neighbour_pass_particle(i)) return;
  vec3 xi = imageLoad(x, int(i)).xyz;
  vec3 eta = vec3(0.0);
  int image;
  FOR_EACH_NEIGHBOUR(i, xi, no_mirrors(), j, image) {
    // The fluid only (a list holds images too); the gradient is zero from r = h on. Only eta's
    // direction is used: its shape keeps it in float's range at every spacing.
    vec3 d = xi - imageLoad(x, int(j)).xyz;
    if (image == 0) eta += length(imageLoad(curl, int(j)).xyz) * spiky_grad_shape(d, length(d));
  }
  float len = length(eta);
  if (len > 0.0) v[i].xyz += (SOLVER_VORTICITY * sim.dt / len) * cross(eta, imageLoad(curl, int(i)).xyz);
}
