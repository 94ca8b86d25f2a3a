#version 450
// The coarse correction, 5 of 5 (contract.h): x_pred += STRENGTH times the coarse solution's
// gradient, interpolated from the eight nodes around it, then out of walls and obstacles.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "contract.h"
#include "coarse.glsl"

layout(constant_id = 7) const float STRENGTH = 0.5;  // Derived::Coarse::strength
layout(binding = 5, rgba32f) uniform imageBuffer x_lambda;  // (x_pred, lambda), constraint_lambda.comp
layout(std430, binding = 6) readonly buffer Grad { vec4 grad[]; };
layout(std430, binding = 9) readonly buffer Phi { float phi[]; };  // coarse_sweep.comp's solution
#define OBSTACLES_BINDING 7
#define WORK_BINDING 8
#define BODY_PUSH_BINDING 10
#define DISTANCES_OUT_BINDING 11  // each particle's distances from the obstacles where it moves (solids.glsl)
#include "solids.glsl"

// The work per unit mass a moving solid does through the correction on a particle of its
// face's first layer: phi is a pressure, the push rho0 STRENGTH grad phi / dt^2 per volume, and
// its reaction on the solid's face the particle stands for (a spacing squared) is
// rho0 STRENGTH phi n / dt^2, which the solid's velocity works (ReferenceSolver::coarse_correction).
float face_work(vec3 x, float p) {
  vec3 normal, velocity;
  float spacing = 2.0 * obstacle_data[0].y;  // the margin is half a spacing
  if (!MOVING || nearest_moving_solid(x, normal, velocity) >= spacing) return 0.0;
  return -sim.rho0 * STRENGTH * p * dot(normal, velocity) * spacing * spacing / (sim.dt * sim.mass);
}

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  vec4 own = imageLoad(x_lambda, int(i));
  vec3 xi = own.xyz;
  CoarseCorner c = coarse_corner(xi);
  vec3 g = vec3(0.0);
  float p = 0.0;
  for (int k = 0; k < 8; ++k) {
    float w;
    int node = coarse_node(c, k, w);
    g += w * grad[node].xyz;
    p += w * phi[node];
  }
  float work = face_work(xi, p);
  vec3 moved = project_out_of_solids(xi + STRENGTH * g, work);
  imageStore(x_lambda, int(i), vec4(moved, own.w));
  if (DISTANCES) keep_distances(i, moved);
  add_work(i, work);
}
