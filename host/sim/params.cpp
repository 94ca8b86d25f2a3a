#include "sim/params.hpp"

#include <cmath>
#include <stdexcept>

#include "sim/kernels.hpp"
#include "sim/lattice.hpp"
#include "sim/stability.hpp"

namespace pbflow {

Method parse_method(const std::string& name) {
  if (name == "pbf") return Method::Pbf;
  if (name == "ldc") return Method::Ldc;
  throw std::invalid_argument("method must be pbf or ldc, not '" + name + "'");
}

const char* method_name(Method m) { return m == Method::Pbf ? "pbf" : "ldc"; }

SolverParams SolverParams::defaults() {
  SolverParams p;
  // The seed paper's claim is about ldc at one iteration; that is what a user gets first.
  p.method = Method::Ldc;
  p.iterations = 1;
  // Adaptive iterations are off unless a scene sets a target (SPlisHSPlasH's PBF stops at
  // an average density error; here the mean compression of DESIGN.md).
  p.target_compression = 0.0;
  p.max_iterations = 100;
  // dt = 1/120 s at 60 fps: a falling column of 0.8 m reaches ~4 m/s, i.e. under
  // two particle spacings (at 0.02 m) per step, the usual PBF budget.
  p.substeps = 2;
  // h = 2 spacings: ~33 neighbours inside h on a lattice (4/3 pi 2^3), the usual SPH choice.
  p.kernel_ratio = 2.0;
  p.rest_density = 1000.0;  // water, kg/m^3
  // eps relative to the denominator's own scale makes the relaxation independent of
  // resolution (an absolute eps would change meaning with spacing). 1% barely slows
  // convergence and keeps lambda bounded for particles with few neighbours.
  p.relaxation = 0.01;
  // One Jacobi pass unrelaxed moves some density modes 2.8x as far as their error (a
  // lattice at h = 2 spacings, host/stability.hpp): past 4/3 a step grows them, and PBF at
  // 1-3 iterations blew up. Gain 1 corrects no mode by more than its own error.
  p.jacobi_gain = 1.0;
  // The relaxation that keeps the worst mode (gain 2.8) sound slows the long modes, which
  // carry the compression, as much. Averaging lambda over the neighbours cuts the worst
  // gain and leaves the long modes': two or four averages, chosen in default_smoothing.
  p.lambda_smoothing = kChosenSmoothing;
  // Macklin & Mueller 2013, section 4: n = 4, dq = 0.2 h, and k = 0.1 there. Off here: the
  // constraint is one-sided (C >= 0), so the negative pressures that clump particles, which
  // the term was made for, do not arise; and its push is a displacement per step whatever
  // dt, i.e. a velocity that grows as 1/dt (the tank at rest blew up at 16 substeps).
  p.scorr_k = 0.0;
  p.scorr_n = 4.0;
  p.scorr_dq = 0.2;
  // XSPH c: 2% of the kernel-averaged relative velocity per step damps particle noise
  // without visibly thickening a dam break.
  p.xsph = 0.02;
  p.vorticity = 0.0;  // off unless a scene asks: it adds energy and a pass
  // The dashpot: 0.2 times the sum's largest eigenvalue (~5 at h = 2 spacings) is 1, the
  // most an explicit damping takes off a mode in one step without reversing it. It stopped
  // the free surface's jitter under ldc@1 and pbf@1's at 40 % compression (README).
  p.damping = 0.2;
  // K as a fraction of the stiffness the step carries (K dt^2 s = 4, host/stability.hpp),
  // so that one value means the same at any dt and spacing. Measured at 60 fps x 2
  // substeps, 0.02 m (README "Physics at the real-time step"): 0.25-0.9 all lose energy in
  // the tank and the dam break, and compress the tank less as it grows (16.9, 10.8, 8.3,
  // 7.2 % at 0.25, 0.5, 0.75, 0.9); 0.5 keeps a margin below the limit.
  p.ldc_strength = 0.5;
  p.ldc_k = -1.0;
  // The seed's force reads a free-surface particle's missing neighbours as low density and
  // pushes the fluid towards the surface: a tank at rest rises by 15 % of its depth and boils
  // (bench/results/). Reading densities below rho0 as rho0 keeps what LDC is for (moving
  // particles out of compressed regions) without that; false gives the seed's force.
  p.ldc_clamp = true;
  // The paper's force compares each rho_j with the particle's own rho_i. At a free surface
  // the neighbours lie on one side, so rho_i's share of the sum pulls the particle towards
  // them, more the denser it reads: a surface particle that slipped into a hollow read
  // denser, lost its support and fell into the fluid at up to 0.14 m/s, and ldc@1's tank
  // at rest never went still (0.08 m/s typical, 0.13 peaks). Against the neighbourhood's
  // weighted mean (the particle included) its own reading barely counts; inside a regular
  // lattice the two agree exactly (the pair terms cancel), so the force's stability limit
  // is unchanged. false gives the paper's force.
  p.ldc_mean_reference = true;
  return p;
}

int default_smoothing(int iterations, double travel) {
  // Two averages cut a pass's worst gain from 2.79 to 0.99, so a pair runs 2.8x bolder:
  // 2.4-3.4x less compression at 2-4 iterations, for two more list passes an iteration.
  // Four cut it to 0.61 (1.6x bolder again). An average costs ~0.4x a lambda or dp pass
  // (peer scene), so in time four reach a compression sooner than more iterations with
  // two: pbf@3 with four 0.86-1.04x the time of pbf@4 with two, pbf@4 with four 0.79-0.97x
  // pbf@6 with two, for the same compression (README). But the pairs' boldness rests on
  // the lattice model, which assumes a step moves less than h: at 1.35 and 1.85 h per
  // step, four averages made 4.8-7.7 % energy where two made none; at 0.67-0.92 h every
  // setting measured was sound. Two iterations keep two: the real-time setting that meets
  // its accuracy (the peer's pbf@2 figure) at the least cost per step.
  return iterations >= 3 && travel <= 1.0 ? 4 : 2;
}

std::vector<Derived::ConstraintPass> Derived::constraint_schedule(int passes) const {
  std::vector<ConstraintPass> schedule;
  for (double w : jacobi_schedule(passes - passes % 2, solver.jacobi_gain, paired_gain_max))
    schedule.push_back({w, solver.lambda_smoothing > 0});
  if (passes % 2) schedule.push_back({jacobi_schedule(1, solver.jacobi_gain, jacobi_gain_max)[0], false});
  return schedule;
}

SimConstants Derived::to_gpu(uint32_t count) const {
  SimConstants c{};
  c.domain_min = domain_min;
  c.h = float(h);
  c.domain_max = domain_max;
  c.dt = float(dt);
  c.gravity = gravity;
  c.mass = float(mass);
  c.grid = grid;
  c.count = count;
  c.wall_min = wall_min;
  c.rho0 = float(rho0);
  c.wall_max = wall_max;
  c.epsilon = float(epsilon);
  c.poly6_coef = float(kernels::poly6_coef(h));
  c.spiky_coef = float(kernels::spiky_coef(h));
  c.ldc_k = float(ldc_k);
  c.scorr_k = float(scorr_scale);
  c.scorr_inv_wdq = float(scorr_inv_wdq);
  c.relax = 1.0f;  // set per constraint pass
  c.xsph_c = float(solver.xsph);
  c.vorticity_eps = float(solver.vorticity);
  return c;
}

}  // namespace pbflow
