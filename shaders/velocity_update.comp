#version 450
// v_i = (x*_i - x_i) / dt; the host then makes x* the new x. The last lambda pass's
// density rides along in v's w, for viscosity_vorticity.comp: it gathers both for every
// neighbour: one gather less per neighbour (docs/performance.md). Where the tank moves, its
// kick's work is its kick times this move, as gravity's is (ReferenceSolver::velocity_update).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(std430, binding = 0) readonly buffer X { vec4 x[]; };
layout(std430, binding = 1) readonly buffer XPred { vec4 x_pred[]; };
layout(std430, binding = 2) buffer V { vec4 v[]; };
layout(std430, binding = 3) readonly buffer Rho { float rho[]; };
#define OBSTACLES_BINDING 4
#define WORK_BINDING 5
#include "solids.glsl"

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  vec3 moved = (x_pred[i].xyz - x[i].xyz) / sim.dt;
  if (tank_kicks()) add_work(i, dot(tank_kick_taken(x[i].xyz, v[i].xyz), moved));
  v[i] = vec4(moved, rho[i]);
}
