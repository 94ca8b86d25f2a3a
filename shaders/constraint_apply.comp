#version 450
// dp_i = (m/rho0) sum_j (lambda_i + lambda_j + s_corr) grad W_spiky(x*_i - x*_j), with the
// tensile term s_corr = -k (W(r)/W(dq))^n (off unless a scene asks); x*_i += relax dp_i,
// then out of walls and obstacles. The pass's relax keeps every density mode's gain per
// step at most one (host/stability.hpp): an unrelaxed Jacobi pass overshoots and makes energy.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(binding = 1, rgba32f) uniform readonly imageBuffer x_lambda;  // (x*, lambda), constraint_lambda.comp
layout(std430, binding = 2) writeonly buffer XOut { vec4 x_out[]; };
#define OBSTACLES_BINDING 3
#include "obstacles.glsl"
// solver.scorr_n; 0 where the term is off (solver.scorr_k = 0, the default): a constant,
// so that its code is compiled out, as llvmpipe would compute it for every entry anyway.
layout(constant_id = 1) const float TENSILE_N = 4.0;
#define NEIGHBOUR_BINDING 4
#define NEIGHBOUR_CAPACITY_ID 2
#include "neighbours.glsl"

// (W(r)/W(dq))^n, by squaring for the usual n = 4: pow() is slow on CPU Vulkan.
float tensile_power(float ratio) {
  if (TENSILE_N == 4.0) {
    float r2 = ratio * ratio;
    return r2 * r2;
  }
  return pow(ratio, TENSILE_N);
}

// (lambda_i + lambda_j + s_corr) grad W_spiky(d), d = x*_i - x*_j (or j's image).
vec3 pair_push(vec3 d, float lambda_ij) {
  float r2 = dot(d, d);
  if (r2 >= sim.h * sim.h) return vec3(0.0);
  float s_corr = TENSILE_N > 0.0 ? -sim.scorr_k * tensile_power(poly6(r2) * sim.scorr_inv_wdq) : 0.0;
  return (lambda_ij + s_corr) * spiky_grad(d, sqrt(r2));
}

void main() {
  uint i;
  if (!neighbour_pass_particle(i)) return;
  vec4 own = imageLoad(x_lambda, int(i));
  vec3 xi = own.xyz;
  WallImages walls = walls_near(xi);
  float lambda_i = own.w;
  vec3 dp = vec3(0.0);
  int image;
  // An image behind a wall carries its particle's lambda; i's own images push i away.
  FOR_EACH_NEIGHBOUR(i, xi, walls, j, image) {
    vec4 xj = imageLoad(x_lambda, int(j));
    dp += pair_push(xi - mirror(walls, image, xj.xyz), lambda_i + xj.w);
  }
  x_out[i] = vec4(project_out_of_solids(xi + sim.relax * (sim.mass / sim.rho0) * dp), 0.0);
}
