#version 450
// The divergence watch, after every step: flags particles whose position or velocity is
// not finite, that move faster than the scene's bound, or that left the domain. The
// host reads the result with the frame's measures (no extra wait) and stops the run.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "contract.h"

layout(std430, binding = 0) readonly buffer X { vec4 x[]; };
layout(std430, binding = 1) readonly buffer V { vec4 v[]; };
layout(std430, binding = 2) buffer Watch { uint watch[WATCH_WORDS]; };  // its words: contract.h
layout(constant_id = 1) const float SPEED_LIMIT = 1e30;  // m/s, from the scene (GpuSolver)

bool finite(vec3 a) { return !any(isnan(a)) && !any(isinf(a)); }

void main() {
  uint i = thread_index();
  if (i >= sim.count) return;
  vec3 xi = x[i].xyz, vi = v[i].xyz;
  uint bad = 0u;
  if (!finite(xi) || !finite(vi)) bad = WATCH_NOT_FINITE;
  else if (dot(vi, vi) > SPEED_LIMIT * SPEED_LIMIT) bad = WATCH_TOO_FAST;
  else if (any(lessThan(xi, sim.domain_min)) || any(greaterThan(xi, sim.domain_max))) bad = WATCH_OUTSIDE;
  const uint step = watch[WATCH_STEP];
  if (bad == 0u || watch[WATCH_FIRST_STEP] < step) return;  // an earlier step failed already: its counts stand
  atomicOr(watch[WATCH_FLAGS], bad);
  atomicMin(watch[WATCH_FIRST_STEP], step);
  atomicAdd(watch[WATCH_COUNTS + findLSB(bad)], 1u);
}
