#version 450
// Per-workgroup partial measures: (sum c_i, max c_i, sum |v_i|^2, max |v_i|^2) and
// (sum of |g| times heights, sum of the moving solids' work per unit mass, 0, 0), c_i = max(rho_i/rho0 - 1, 0), heights measured
// along -g from the domain's lowest corner (docs/design.md's potential energy, per unit mass). reduce_final.comp combines the partials.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x = 256) in;
#include "common.glsl"

layout(std430, binding = 0) readonly buffer Rho { float rho[]; };
layout(std430, binding = 1) readonly buffer V { vec4 v[]; };
layout(std430, binding = 2) readonly buffer X { vec4 x[]; };
layout(std430, binding = 3) writeonly buffer Partials { vec4 partials[]; };
layout(std430, binding = 4) readonly buffer Work { float work[]; };  // solids.glsl's
layout(constant_id = 91) const bool MOVING = false;

shared vec4 acc[256];
shared vec2 potential_acc[256];  // and the work

// Potential energy per unit mass at p: |g| times its height above the domain's lowest corner.
float potential_at(vec3 p) {
  vec3 lowest = mix(sim.domain_min, sim.domain_max, greaterThan(sim.gravity, vec3(0.0)));
  return dot(-sim.gravity, p - lowest);
}

void main() {
  uint i = thread_index();
  uint t = gl_LocalInvocationID.x;
  vec4 mine = vec4(0.0);
  vec2 potential = vec2(0.0);
  if (i < sim.count) {
    potential = vec2(potential_at(x[i].xyz), MOVING ? work[i] : 0.0);
    float c = max(rho[i] / sim.rho0 - 1.0, 0.0);
    float s2 = dot(v[i].xyz, v[i].xyz);
    mine = vec4(c, c, s2, s2);
  }
  acc[t] = mine;
  potential_acc[t] = potential;
  barrier();
  for (uint half_ = 128; half_ > 0; half_ >>= 1) {
    if (t < half_) {
      vec4 a = acc[t], b = acc[t + half_];
      acc[t] = vec4(a.x + b.x, max(a.y, b.y), a.z + b.z, max(a.w, b.w));
      potential_acc[t] += potential_acc[t + half_];
    }
    barrier();
  }
  uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  if (t == 0) {
    partials[2 * group] = acc[0];
    partials[2 * group + 1] = vec4(potential_acc[0], 0.0, 0.0);
  }
}
