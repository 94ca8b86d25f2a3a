#version 450
// The particles' smoothed positions, for drawing the fluid's surface (Yu & Turk 2013):
// x_i + POSITION_SMOOTHING (mean_j x_j - x_i), the mean weighted by 1 - (r/h)^3 over the neighbours
// and their images behind the walls, i itself included. Inside the fluid the mean is the
// particle's own place; at the free surface it lies inward, so a surface's particles are
// drawn closer to a plane: a lattice's rows and columns, a spacing apart, no longer show as
// bands, and a settled top lies flatter. The walls' images keep a particle at a wall where
// it is. Written once a frame where the capture asks (Solver::set_smoothed_positions).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "contract.h"

layout(binding = 1, rgba32f) uniform readonly imageBuffer x;
layout(std430, binding = 2) writeonly buffer XSmooth { vec4 x_smooth[]; };
#define NEIGHBOUR_BINDING 3
#define NEIGHBOUR_CAPACITY_ID 1
#include "neighbours.glsl"

void main() {
  uint i;
  if (!neighbour_pass_particle(i)) return;
  vec3 xi = imageLoad(x, int(i)).xyz;
  WallImages walls = walls_near(xi);
  vec3 sum = vec3(0.0);
  float weights = 0.0;
  int image;
  FOR_EACH_NEIGHBOUR(i, xi, walls, j, image) {
    vec3 xj = mirror(walls, image, imageLoad(x, int(j)).xyz);
    float w = position_weight(xi - xj);
    sum += w * xj;
    weights += w;
  }
  x_smooth[i] = vec4(mix(xi, sum / weights, float(POSITION_SMOOTHING)), 0.0);
}
