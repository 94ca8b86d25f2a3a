#version 450
// Local density correction (LDC): f_i = -K sum_j ((rho_j - rho_i)/rho0) h (1 - r/h) (x_j - x_i)/r,
// pushing each particle away from denser neighbours; applied at once as v_i += f_i dt, and
// then the prediction, as predict.comp's: v_i += g dt, x*_i = x_i + v_i dt. In this pass
// rather than a pass of its own: a dispatch less (docs/performance.md).
// With SOLVER_LDC_CLAMP densities below rho0 count as rho0, so that a
// free surface (neighbours missing, density low) does not draw the fluid towards it.
// Within h of a wall the sum also runs over the neighbours' mirror images behind it (the
// walls' ghost fluid, common.glsl): without them a particle at a wall got half the force
// that holds up a compressed column, sank, and drove a jet down every wall.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(binding = 1, rgba32f) uniform readonly imageBuffer x;
layout(binding = 2, r32f) uniform readonly imageBuffer rho;
layout(std430, binding = 3) buffer V { vec4 v[]; };
layout(std430, binding = 6) writeonly buffer XPred { vec4 x_pred[]; };
#define OBSTACLES_BINDING 7
#define WORK_BINDING 8
#define BODY_PUSH_BINDING 9
#include "solids.glsl"
layout(constant_id = 100) const bool SOLVER_LDC_CLAMP = false;  // the scene's key (gpu/key_constants.hpp)
layout(constant_id = 2) const float LDC_ROOM = 1.8;  // Derived::ldc_room
#define NEIGHBOUR_BINDING 4
#define CREASES_BINDING 10
#define NEIGHBOUR_CAPACITY_ID 3
#include "neighbours.glsl"

float density_of(uint k) { return imageLoad(rho, int(k)).x; }
float ldc_density(uint k) { return SOLVER_LDC_CLAMP ? max(density_of(k), sim.rho0) : density_of(k); }

// One neighbour's geometric term, h(1 - r/h) d/r = (h - r) d/r.
vec3 pair_term(vec3 d) {
  float r2 = dot(d, d);
  if (r2 >= sim.h * sim.h || r2 == 0.0) return vec3(0.0);
  float r = sqrt(r2);
  return ((sim.h - r) / r) * d;
}

void main() {
  uint i;
  if (!neighbour_pass_particle(i)) return;
  vec3 xi = imageLoad(x, int(i)).xyz;
  Mirrors mirrors = neighbour_mirrors(i, xi);
  mirrors.listed = mirrors.listed && !MOVING;  // the last step's lists, and Move came since
  // Differences keep the float sum exact at uniform density.
  float rho_i = ldc_density(i);
  vec3 f = vec3(0.0), f_solid = vec3(0.0);  // and the obstacle's images' share
  int image;
  FOR_EACH_NEIGHBOUR(i, xi, mirrors, j, image) {  // an image carries its particle's density
    vec3 xj = mirror(mirrors, image, j, imageLoad(x, int(j)).xyz);
    vec3 term = (ldc_density(j) - rho_i) * pair_term(xj - xi);
    f += term;
    if (MOVING && solid_image(mirrors, image)) f_solid += term;
  }
  // The force's stiffness grows with the neighbours inside h, by up to (rho/rho0)^2 on a
  // squeezed lattice (host/sim/stability.hpp): K, a fraction of what the step carries at rho0,
  // is capped where that would pass kLdcCap of the limit.
  float squeeze = max(density_of(i), sim.rho0) / sim.rho0;
  float k_i = sim.ldc_k * min(1.0, LDC_ROOM / (squeeze * squeeze));
  vec3 vi = v[i].xyz + (-k_i / sim.rho0 * sim.dt) * f;
  vec3 kick = tank_kick(xi, vi);
  vi += sim.gravity * sim.dt + kick;
  v[i].xyz = vi;
  // The images' force does work at the solid's velocity over the step (the tank's motion's:
  // velocity_update.comp's).
  vec3 f_images = (-k_i / sim.rho0) * f_solid;
  float work = 0.0;
  if (!push_body(mirrors.obstacle, xi, f_images * (sim.dt * sim.dt))) work += dot(f_images, mirrors.solid_velocity) * sim.dt;
  x_pred[i] = vec4(predicted_position(xi, vi, work), 0.0);
  add_work(i, work);
}
