#version 450
// dp_i = (m/rho0) sum_j (lambda_i + lambda_j) grad W_spiky(x*_i - x*_j); x*_i += relaxation * dp_i,
// then out of walls and obstacles. The pass's relaxation keeps every density mode's gain per
// step at most one (host/sim/stability.hpp): an unrelaxed Jacobi pass overshoots and makes energy.
// Macklin & Mueller's tensile term is not here: it pushes a fixed distance a step whatever
// dt, so smaller steps were less stable with it (the tank at rest blew up at 16 substeps),
// and the constraint is one-sided (C >= 0), so the negative pressures it was made for do
// not arise (docs/physics.md).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(binding = 1, rgba32f) uniform readonly imageBuffer x_lambda;  // (x*, lambda), constraint_lambda.comp
layout(std430, binding = 2) writeonly buffer XOut { vec4 x_out[]; };
#define OBSTACLES_BINDING 3
#define WORK_BINDING 6
#define BODY_PUSH_BINDING 7
#define DISTANCES_BINDING 9  // the neighbours' distances from the obstacles (solids.glsl)
#define DISTANCES_OUT_BINDING 10  // and each particle's where this pass moves it
#include "solids.glsl"
#define NEIGHBOUR_BINDING 4
#define CREASES_BINDING 8
#define NEIGHBOUR_CAPACITY_ID 2
#include "neighbours.glsl"

void main() {
  uint i;
  if (!neighbour_pass_particle(i)) return;
  vec4 own = imageLoad(x_lambda, int(i));
  vec3 xi = own.xyz;
  Mirrors mirrors = neighbour_mirrors(i, xi);
  float lambda_i = own.w;
  vec3 dp = vec3(0.0), dp_solid = vec3(0.0);  // and the obstacle's images' share
  int image;
  // An image behind a wall carries its particle's lambda; i's own images push i away.
  FOR_EACH_NEIGHBOUR(i, xi, mirrors, j, image) {
    vec4 xj = imageLoad(x_lambda, int(j));
    vec3 d = xi - mirror(mirrors, image, j, xj.xyz);
    vec3 term = (lambda_i + xj.w) * spiky_grad(d, length(d));
    dp += term;
    if (MOVING && solid_image(mirrors, image)) dp_solid += term;
  }
  float scale = sim.relaxation * (sim.mass / sim.rho0);
  float work = MOVING && !push_body(mirrors.obstacle, xi, scale * dp_solid) ? dot(scale * dp_solid, mirrors.solid_velocity) / sim.dt : 0.0;
  vec3 moved = project_out_of_solids(xi + scale * dp, work);
  x_out[i] = vec4(moved, 0.0);
  if (DISTANCES) keep_distances(i, moved);
  add_work(i, work);
}
