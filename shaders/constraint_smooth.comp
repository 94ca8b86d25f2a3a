#version 450
// lambda_i <- the weighted mean of lambda_j over i's neighbours (i and the walls' mirror
// images included; weight 1 - (r/h)^8): one of the solver.lambda_smoothing passes between
// constraint_lambda and constraint_apply.
// Why: a Jacobi pass corrects a density mode by its gain, and the under-relaxation that
// keeps the worst mode (~5 spacings long, gain 2.8 unrelaxed) sound scales the long modes,
// which hold the compression, down with it. Averaging twice multiplies each mode's gain by
// F(k)^2, F the weighted mean of cos(k.o): near 1 for long modes, small for the worst one,
// never negative; a pair of passes can then be 2.8x bolder (host/sim/stability.cpp).
// The weight is nearly flat inside h (a flat one smooths most) and reaches 0 at h: an
// unweighted mean jumps when a neighbour crosses h, and on a lattice at h = 2 spacings
// the six axis neighbours sit exactly there (float rounding then decided the mean).
// The images carry their particle's lambda: near a wall the fluid is then the lattice
// restricted to mirror-symmetric modes, which the model covers.
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(binding = 1, rgba32f) uniform readonly imageBuffer x_lambda_in;  // (x*, lambda), constraint_lambda.comp
layout(std430, binding = 2) writeonly buffer XLambdaOut { vec4 x_lambda_out[]; };
#define OBSTACLES_BINDING 5
#define NEIGHBOUR_BINDING 3
#define CREASES_BINDING 6
#define DISTANCES_BINDING 7  // the neighbours' distances from the obstacles (solids.glsl)
#define NEIGHBOUR_CAPACITY_ID 1
#include "neighbours.glsl"

void main() {
  uint i;
  if (!neighbour_pass_particle(i)) return;
  vec3 xi = imageLoad(x_lambda_in, int(i)).xyz;
  Mirrors mirrors = neighbour_mirrors(i, xi);
  float sum = 0.0, total = 0.0;
  int image;
  FOR_EACH_NEIGHBOUR(i, xi, mirrors, j, image) {  // an image carries its particle's lambda
    vec4 xj = imageLoad(x_lambda_in, int(j));
    float w = smoothing_weight(xi - mirror(mirrors, image, j, xj.xyz));
    sum += w * xj.w;
    total += w;
  }
  x_lambda_out[i] = vec4(xi, sum / total);  // total >= 1: i is its own neighbour at r = 0
}
