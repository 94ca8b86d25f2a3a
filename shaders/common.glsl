// Shared by every particle pass: the simulation constants (mirrors SimConstants in
// host/params.hpp), the SPH kernels (mirrors host/kernels.hpp) and the grid lookup.

layout(push_constant) uniform Sim {
  vec3 domain_min; float h;
  vec3 domain_max; float dt;
  vec3 gravity; float mass;
  ivec3 grid; uint count;
  vec3 wall_min; float rho0;
  vec3 wall_max; float epsilon;
  float poly6_coef; float spiky_coef; float ldc_k; float scorr_k;  // scorr_k: k / (interior sum |grad C|^2)
  float scorr_inv_wdq; float relax; float xsph_c; float vorticity_eps;  // relax: this Jacobi pass's
} sim;

// Dispatches larger than the group-count limit fold into y (CommandList::dispatch).
uint thread_index() {
  return gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
}

// poly6: W(r) = 315/(64 pi h^9) (h^2 - r^2)^3 for r < h.
float poly6(float r2) {
  float d = sim.h * sim.h - r2;
  return d > 0.0 ? sim.poly6_coef * d * d * d : 0.0;
}

// Gradient of the spiky kernel with respect to x_i, for d = x_i - x_j and r = |d|:
// -45/(pi h^6) (h - r)^2 d/r for 0 < r < h.
vec3 spiky_grad(vec3 d, float r) {
  if (r <= 0.0 || r >= sim.h) return vec3(0.0);
  float s = sim.h - r;
  return (-sim.spiky_coef * s * s / r) * d;
}

// Walls as the fluid's lattice continued past them (host/kernels.hpp says why): the
// fraction of a particle's poly6 sum that the layers beyond a wall at distance a would
// give, F(a) = sum_n l(a + (n + 1/2) s) / sum_m l(m s), l(d) = (1 - d^2/h^2)^4, and dF/da.
// The spacing s is twice the gap between a wall and the outermost centres.
float spacing() { return 2.0 * (sim.wall_min.x - sim.domain_min.x); }
float lattice_layers() {
  float s = spacing(), sum = 1.0;
  for (float d = s; d < sim.h; d += s) {
    float t = 1.0 - d * d / (sim.h * sim.h);
    sum += 2.0 * t * t * t * t;
  }
  return sum;
}
vec2 wall_layers(float a) {  // (F, dF/da) times lattice_layers(): wall_density divides once
  float s = spacing();
  vec2 sum = vec2(0.0);
  for (float d = max(a, 0.0) + 0.5 * s; d < sim.h; d += s) {
    float t = 1.0 - d * d / (sim.h * sim.h);
    sum += vec2(t * t * t * t, -8.0 * d / (sim.h * sim.h) * t * t * t);
  }
  return sum;
}
// The walls' density at x and its gradient with respect to x. The kept fractions
// (1 - F) multiply, so that at edges and corners the volume behind two or three walls
// is not counted twice.
float wall_density(vec3 x, out vec3 grad) {
  vec3 lo = x - sim.domain_min, hi = sim.domain_max - x;
  float kept = 1.0;
  vec3 dlog;  // d log(kept) / dx
  float layers = lattice_layers();
  for (int a = 0; a < 3; ++a) {
    vec2 f_lo = wall_layers(lo[a]) / layers, f_hi = wall_layers(hi[a]) / layers;
    kept *= (1.0 - f_lo.x) * (1.0 - f_hi.x);
    dlog[a] = -f_lo.y / (1.0 - f_lo.x) + f_hi.y / (1.0 - f_hi.x);
  }
  grad = -sim.rho0 * kept * dlog;
  return sim.rho0 * (1.0 - kept);
}

ivec3 cell_of(vec3 x) {
  // Clamp in float first (a far-away position must not overflow the int), then in int:
  // a NaN converts to an undefined int, and the int clamp keeps even that inside the
  // grid, so a diverged particle never indexes out of bounds (the watch reports it).
  vec3 c = clamp(floor((x - sim.domain_min) / sim.h), vec3(0.0), vec3(sim.grid - 1));
  return clamp(ivec3(c), ivec3(0), sim.grid - 1);
}

uint cell_id(ivec3 c) { return uint((c.z * sim.grid.y + c.y) * sim.grid.x + c.x); }

vec3 project_to_walls(vec3 x) { return clamp(x, sim.wall_min, sim.wall_max); }

// Loops j over every particle binned in the 27 cells around position xi (the body
// tests the distance). Cells are numbered x-fastest, so each row of three cells is
// one contiguous range of the sorted particles: nine ranges instead of 27.
// Needs a buffer `cell_start` (exclusive prefix sum of particles per cell).
#define FOR_EACH_NEIGHBOUR(xi, j)                                                         \
  ivec3 c_##j = cell_of(xi);                                                              \
  int lo_##j = max(c_##j.x - 1, 0), hi_##j = min(c_##j.x + 1, sim.grid.x - 1);            \
  for (int z_##j = max(c_##j.z - 1, 0); z_##j <= min(c_##j.z + 1, sim.grid.z - 1); ++z_##j) \
    for (int y_##j = max(c_##j.y - 1, 0); y_##j <= min(c_##j.y + 1, sim.grid.y - 1); ++y_##j) \
      for (uint j = cell_start[cell_id(ivec3(lo_##j, y_##j, z_##j))],                     \
                end_##j = cell_start[cell_id(ivec3(hi_##j, y_##j, z_##j)) + 1];           \
           j < end_##j; ++j)
