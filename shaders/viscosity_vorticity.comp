#version 450
// From the same velocities (V_j = m/rho0):
// - XSPH viscosity, v_i += c sum_j V_j (v_j - v_i) W_ij;
// - a pairwise dashpot on the relative normal velocity,
//   v_i -= sum_j c_ij (1 - r/h) ((v_i - v_j).d) d / r^2 (d = x_j - x_i), c_ij = SOLVER_DAMPING
//   unless the pair is squeezed (below);
// - the vorticity's curl w_i = sum_j V_j (v_j - v_i) x grad W_ij;
// - and, as density.comp computes it, rho_i at x: the next step's LDC force and the frame's
//   measures read it. XSPH already takes poly6 of every fluid entry; summing it over all
//   entries (the images' too) costs an add each, where a density pass costs a walk.
// Why the dashpot: an explicit stiffness maps a density mode as q' = 2q - q_prev - nu q,
// undamped for every nu < 4, so the LDC force at the free surface (where the constraint is
// idle) and a saturated Jacobi pass leave modes jittering. The dashpot is symmetric in i and j: it keeps
// momentum and only removes energy; it acts on approach and separation along d only, so
// a rigid motion (translation, rotation) passes untouched. The neighbours' images behind
// the walls (common.glsl) take part too, moving as their particle mirrored: against its
// own image a particle's velocity normal to a wall is damped, along the wall it is free.
// Without them a squeezed particle in a bottom corner (pbf@1, ~1.9 rho0) swung normal to
// the walls at ~0.1 m/s in a tank at rest. Every image term removes energy, as a pair's.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(constant_id = 100) const float SOLVER_XSPH = 0.0;     // the scene's keys (gpu/key_constants.hpp)
layout(constant_id = 101) const float SOLVER_DAMPING = 0.0;
layout(constant_id = 102) const float SOLVER_VORTICITY = 0.0;
layout(constant_id = 2) const float DAMPING_LIMIT = 0.3;   // Derived::damping_limit
// The curl is wanted only for vorticity_force.comp; without it the curl, a cross product and a
// kernel gradient per neighbour, is not computed (a constant once specialised: the driver
// drops the branch; docs/performance.md).
#define VORTICITY (SOLVER_VORTICITY > 0.0)

layout(binding = 1, rgba32f) uniform readonly imageBuffer x;
// v, and in w the last lambda pass's rho (velocity_update.comp)
layout(binding = 2, rgba32f) uniform readonly imageBuffer v_rho;
layout(std430, binding = 3) writeonly buffer VOut { vec4 v_out[]; };
layout(std430, binding = 4) writeonly buffer Curl { vec4 curl[]; };  // VORTICITY only
layout(std430, binding = 5) writeonly buffer Rho { float rho[]; };
#define OBSTACLES_BINDING 8
#define WORK_BINDING 9
#define BODY_PUSH_BINDING 10
#define NEIGHBOUR_BINDING 6
#define CREASES_BINDING 11
#define DISTANCES_BINDING 12  // the neighbours' distances from the obstacles (solids.glsl)
#define NEIGHBOUR_CAPACITY_ID 4
#include "neighbours.glsl"

// The velocity change of i from a dashpot of coefficient c to a partner at x_i - d moving
// at v_i + vij; nothing beyond h, nothing from a partner at i's own place.
vec3 dashpot(vec3 d, vec3 vij, float c) {
  float r2 = dot(d, d);
  if (r2 >= sim.h * sim.h || r2 == 0.0) return vec3(0.0);
  return (c * (1.0 - sqrt(r2) / sim.h) * dot(vij, d) / r2) * d;
}

void main() {
  uint i;
  if (!neighbour_pass_particle(i)) return;
  vec3 xi = imageLoad(x, int(i)).xyz;
  vec4 own = imageLoad(v_rho, int(i));
  vec3 vi = own.xyz;
  vec3 smooth_v = vec3(0.0);
  vec3 curl_i = vec3(0.0);
  vec3 damp = vec3(0.0), damp_solid = vec3(0.0);  // and the obstacle's images' share
  float density = 0.0;
  float rho_i = max(own.w, sim.rho0);
  float volume = sim.mass / sim.rho0;
  Mirrors mirrors = neighbour_mirrors(i, xi);
  int image;
  FOR_EACH_NEIGHBOUR(i, xi, mirrors, j, image) {
    vec3 xj = imageLoad(x, int(j)).xyz, d = xi - mirror(mirrors, image, j, xj);
    float r2 = dot(d, d);  // every term below is zero from r = h on
    vec4 vj = imageLoad(v_rho, int(j));
    vec3 vij = mirror_velocity(mirrors, image, vj.xyz) - vi;  // an image moves as j, mirrored
    float w = poly6(r2);
    density += w;
    if (image == 0) {  // XSPH and the vorticity see the fluid only
      smooth_v += vij * w;
      if (VORTICITY) curl_i += cross(vij, spiky_grad(d, sqrt(r2)));
    }
    // The dashpot's largest eigenvalue grows with the neighbours inside h, images included
    // (by less than rho/rho0 on a squeezed lattice): a pair is damped by at most
    // DAMPING_LIMIT times the denser one's rho0/rho, so no mode is driven (2.4x at 3x rho0
    // drove them: blow-up).
    float c = min(SOLVER_DAMPING, DAMPING_LIMIT * sim.rho0 / max(rho_i, vj.w));
    vec3 pushed = dashpot(d, vij, c);
    if (STICKY) pushed += (NO_SLIP_GAIN * volume * w) * stick(mirrors, image, vi, vj.xyz);
    damp += pushed;
    if (MOVING && solid_image(mirrors, image)) damp_solid += pushed;
  }
  v_out[i] = vec4(vi + (SOLVER_XSPH * volume) * smooth_v + damp, 0.0);
  if (VORTICITY) curl[i] = vec4(volume * curl_i, 0.0);
  rho[i] = sim.mass * density;
  if (!push_body(mirrors.obstacle, xi, damp_solid)) add_work(i, dot(damp_solid, mirrors.solid_velocity));  // the images' drag
}
