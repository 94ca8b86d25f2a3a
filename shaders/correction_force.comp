#version 450
// Local density correction (LDC): f_i = -K sum_j ((rho_j - rho_i)/rho0) h (1 - r/h) (x_j - x_i)/r,
// pushing each particle away from denser neighbours; applied at once as v_i += f_i dt.
// With CLAMP_DENSITY (solver.ldc_clamp) densities below rho0 count as rho0, so that a
// free surface (neighbours missing, density low) does not draw the fluid towards it.
// Within h of a wall the sum also runs over the neighbours' mirror images behind it (the
// walls' ghost fluid, common.glsl): without them a particle at a wall got half the force
// that holds up a compressed column, sank, and drove a jet down every wall.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(std430, binding = 0) readonly buffer CellStart { uint cell_start[]; };
layout(std430, binding = 1) readonly buffer X { vec4 x[]; };
layout(std430, binding = 2) readonly buffer Rho { float rho[]; };
layout(std430, binding = 3) buffer V { vec4 v[]; };
layout(constant_id = 1) const bool CLAMP_DENSITY = true;
layout(constant_id = 2) const float LDC_ROOM = 1.8;  // Derived::ldc_room
#define NEIGHBOUR_BINDING 4
#define NEIGHBOUR_CAPACITY_ID 3
#include "neighbours.glsl"

float ldc_density(uint k) { return CLAMP_DENSITY ? max(rho[k], sim.rho0) : rho[k]; }

// One neighbour's term, h(1 - r/h) = h - r.
vec3 pair_term(vec3 d, float rho_difference) {
  float r2 = dot(d, d);
  if (r2 >= sim.h * sim.h || r2 == 0.0) return vec3(0.0);
  float r = sqrt(r2);
  return (rho_difference * (sim.h - r) / r) * d;
}

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  vec3 xi = x[i].xyz;
  float rho_i = ldc_density(i);
  WallImages walls = walls_near(xi);
  vec3 f = vec3(0.0);
  FOR_EACH_NEIGHBOUR(i, xi, j) {
    vec3 xj = x[j].xyz;
    float difference = ldc_density(j) - rho_i;
    f += pair_term(xj - xi, difference);
    for (int k = walls.axes; k != 0; k = next_image(walls, k)) f += pair_term(mirror(walls, k, xj) - xi, difference);
  }
  // The force's stiffness grows with the neighbours inside h, by up to (rho/rho0)^2 on a
  // squeezed lattice (host/stability.hpp): K, a fraction of what the step carries at rho0,
  // is capped where that would pass kLdcCap of the limit. Uncapped, ldc@1 at 0.5 passed the
  // limit at ~50 % compression, and the dam break at 0.01 m oscillated and blew up.
  float squeeze = max(rho[i], sim.rho0) / sim.rho0;
  float k_i = sim.ldc_k * min(1.0, LDC_ROOM / (squeeze * squeeze));
  v[i].xyz += (-k_i / sim.rho0 * sim.dt) * f;
}
