#version 450
// lambda_i = -C_i / (sum_k |grad_k C_i|^2 + eps), C_i = max(rho_i/rho0 - 1, 0) at the predicted positions.
// rho_i is kept too: adaptive iterations measure the compression from it (check_converged).
// lambda_i goes out beside x*_i, as (x*_i, lambda_i): the passes after it gather both for
// every neighbour, and one gather instead of two saves each a few per cent on llvmpipe
// (an extra gather per neighbour cost ~15 % of a lambda average, measured when gathers
// were texel fetches: bench/results/throughput_lavapipe.md).
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"

layout(binding = 1, rgba32f) uniform readonly imageBuffer x_pred;
layout(std430, binding = 2) writeonly buffer XLambda { vec4 x_lambda[]; };
layout(std430, binding = 3) writeonly buffer Rho { float rho_out[]; };
#define NEIGHBOUR_BINDING 4
#define NEIGHBOUR_CAPACITY_ID 1
#include "neighbours.glsl"

void main() {
  uint i;
  if (!neighbour_pass_particle(i)) return;
  vec3 xi = imageLoad(x_pred, int(i)).xyz;
  WallImages walls = walls_near(xi);
  float w_sum = 0.0;
  vec3 grad_i = vec3(0.0);  // grad of C_i with respect to x_i, times rho0/m
  float grad_sq = 0.0;      // sum over j != i of |grad_j C_i|^2, times (rho0/m)^2
  int image;
  // The fluid first: for j = i the kernel gradient is zero.
  FOR_EACH_NEIGHBOUR_IN(FLUID_ENTRIES, i, xi, walls, j, image) {
    vec3 d = xi - imageLoad(x_pred, int(j)).xyz;
    float r2 = dot(d, d);
    w_sum += poly6(r2);
    vec3 g = spiky_grad(d, sqrt(r2));
    grad_i += g;
    grad_sq += dot(g, g);
  }
  // Then the images, of neighbour m, in a walk of their own: their bookkeeping, run for
  // every entry of a single walk, cost the pass ~2.5 ms of 10 (dam break ldc@1, ~100k
  // particles; the constraints 18.8 -> 16.2-16.9 ms a step with two walks).
  // -grad_m C_i sums m's own term and its images' (m moves them too, reflected), so the
  // images of one m, which follow each other in the list, are summed in g_m before
  // squaring; g_m starts from m's own term, whose square m's fluid entry added.
  uint image_of = i;  // the particle g_m belongs to (i: none yet)
  vec3 g_m = vec3(0.0), g_own = vec3(0.0);
  FOR_EACH_NEIGHBOUR_IN(IMAGE_ENTRIES, i, xi, walls, m, image) {
    vec3 xm = imageLoad(x_pred, int(m)).xyz, d = xi - mirror(walls, image, xm);
    float r2 = dot(d, d);
    w_sum += poly6(r2);
    vec3 g = spiky_grad(d, sqrt(r2));
    // i's own images move with i, away from it: they count twice in grad_i C_i.
    grad_i += m == i ? 2.0 * g : g;
    if (m != i) {  // no `continue` here: it would keep the loop from unrolling (neighbours.glsl)
      if (m != image_of) {  // the first image of m: close the last one's sum, open m's
        grad_sq += dot(g_m, g_m) - dot(g_own, g_own);
        vec3 dm = xi - xm;
        g_own = g_m = spiky_grad(dm, sqrt(dot(dm, dm)));
        image_of = m;
      }
      g_m += mirror_sign(image) * g;
    }
  }
  grad_sq += dot(g_m, g_m) - dot(g_own, g_own);
  float rho = sim.mass * w_sum;
  float s = sim.mass / sim.rho0;
  vec3 own = s * grad_i;  // grad_i C_i
  float c = max(rho / sim.rho0 - 1.0, 0.0);
  rho_out[i] = rho;
  // A pass's gain grows with the neighbours inside h: the relaxation, sized at rho0, shrinks
  // as 1 / (1 + c / 3), the growth a squeezed lattice shows (host/stability.hpp,
  // kCompressedGain). Without it pbf@1 blew up in the dam break (+46 % energy); with
  // 1 / (1 + c) it could not hold the column and collapsed to the floor.
  const float COMPRESSED_GAIN = 1.0 / 3.0;
  x_lambda[i] = vec4(xi, -c / ((s * s * grad_sq + dot(own, own) + sim.epsilon) * (1.0 + COMPRESSED_GAIN * c)));
}
