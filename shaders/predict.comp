#version 450
// v_i += g dt; x*_i = x_i + v_i dt, kept inside the walls and out of the obstacles. With LDC
// the correction pass predicts instead (correction_force.comp), in the same order.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(std430, binding = 0) readonly buffer X { vec4 x[]; };
layout(std430, binding = 1) buffer V { vec4 v[]; };
layout(std430, binding = 2) writeonly buffer XPred { vec4 x_pred[]; };
#define OBSTACLES_BINDING 3
#define WORK_BINDING 4
#define BODY_PUSH_BINDING 5
#include "solids.glsl"

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  vec3 kick = tank_kick(x[i].xyz, v[i].xyz);
  vec3 vi = v[i].xyz + sim.gravity * sim.dt + kick;
  v[i].xyz = vi;
  float work = 0.0;  // the tank's motion's: velocity_update.comp's
  x_pred[i] = vec4(predicted_position(x[i].xyz, vi, work), 0.0);
  add_work(i, work);
}
