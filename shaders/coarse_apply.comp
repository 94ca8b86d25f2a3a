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
#define OBSTACLES_BINDING 7
#include "solids.glsl"

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  vec4 own = imageLoad(x_lambda, int(i));
  vec3 xi = own.xyz;
  CoarseCorner c = coarse_corner(xi);
  vec3 g = vec3(0.0);
  for (int k = 0; k < 8; ++k) {
    float w;
    int node = coarse_node(c, k, w);
    g += w * grad[node].xyz;
  }
  imageStore(x_lambda, int(i), vec4(project_out_of_solids(xi + STRENGTH * g), own.w));
}
