#version 450
// lambda_i = -C_i / (sum_k |grad_k C_i|^2 + eps), C_i = max(rho_i/rho0 - 1, 0) at the predicted positions.
// rho_i is kept too: adaptive iterations measure the compression from it (check_converged).
// lambda_i goes out beside x*_i, as (x*_i, lambda_i): the passes after it gather both for
// every neighbour, and one gather instead of two saves each a few per cent
// (docs/performance.md, "Measurements behind the code").
#extension GL_GOOGLE_include_directive : require
layout(local_size_x_id = 0) in;
#include "common.glsl"
#include "contract.h"

layout(binding = 1, rgba32f) uniform readonly imageBuffer x_pred;
layout(std430, binding = 2) writeonly buffer XLambda { vec4 x_lambda[]; };
layout(std430, binding = 3) writeonly buffer Rho { float rho_out[]; };
#define OBSTACLES_BINDING 6
#define NEIGHBOUR_BINDING 4
#define CREASES_BINDING 7
#define DISTANCES_BINDING 8  // the neighbours' distances from the obstacles (solids.glsl)
#define NEIGHBOUR_CAPACITY_ID 1
#include "neighbours.glsl"

void main() {
  uint i;
  if (!neighbour_pass_particle(i)) return;
  vec3 xi = imageLoad(x_pred, int(i)).xyz;
  Mirrors mirrors = neighbour_mirrors(i, xi);
  // m/rho0 goes into every gradient term before it is squared: the squares alone, ~1/h^8,
  // leave float's range at the ends of particle_spacing's (tests/scale_test.cpp).
  const float s = sim.mass / sim.rho0;
  float w_sum = 0.0;
  vec3 grad_i = vec3(0.0);  // grad of C_i with respect to x_i
  float grad_sq = 0.0;      // sum over the neighbours k != i of |grad_k C_i|^2
  int image;
  // The walls are mirrors (common.glsl): behind them lies the fluid reflected. A neighbour's
  // image is a neighbour of its own, its term squared on its own as a fluid neighbour's:
  // the mirrored fluid is then the lattice, and a particle beside a wall meets the sum one
  // inside meets (summed with its particle's term first, the sum is larger beside the walls
  // and the pass weaker there).
  // i's own images are no other particle's: they move with i, mirrored, so their distance
  // to i changes twice as fast and their term counts twice in grad_i C_i. Taken as
  // neighbours of their own instead, the settled tank's corner columns slid down in
  // ldc@1 (0.03-0.105 m/s over the last second of tests/rest_test.cpp, against 0.010-0.026).
  // On a lattice beside a face the two agree (all terms sum to zero there); at an edge or a
  // corner the doubled images' cross terms leave the sum a little larger than inside.
  FOR_EACH_NEIGHBOUR(i, xi, mirrors, j, image) {  // for j = i itself the kernel gradient is zero
    vec3 d = xi - mirror(mirrors, image, j, imageLoad(x_pred, int(j)).xyz);
    float r2 = dot(d, d);
    w_sum += poly6(r2);
    vec3 g = s * spiky_grad(d, sqrt(r2));
    bool own_image = j == i;
    grad_i += own_image ? 2.0 * g : g;
    grad_sq += own_image ? 0.0 : dot(g, g);
  }
  float rho = sim.mass * w_sum;
  float c = max(rho / sim.rho0 - 1.0, 0.0);
  rho_out[i] = rho;
  // A pass's gain grows with the neighbours inside h: the relaxation, sized at rho0, shrinks
  // as 1 / (1 + c / 3), the growth a squeezed lattice shows (host/sim/stability.hpp).
  x_lambda[i] = vec4(xi, -c / ((grad_sq + dot(grad_i, grad_i) + sim.epsilon) * (1.0 + float(COMPRESSED_GAIN) * c)));
}
