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

int default_smoothing(int iterations, double travel) {
  // Two averages cut a pass's worst gain from 2.79 to 0.99, so a pair runs 2.8x bolder.
  // Four averages cut the worst gain to 0.61, 1.6x bolder than two, and an average costs
  // ~0.4 of a lambda pass, so from three iterations four reach a compression sooner. The
  // boldness rests on the lattice model, which holds while a step moves less than h
  // (docs/physics.md, "Smoothed λ for paired passes"). Two iterations keep two.
  return iterations >= 3 && travel <= 1.0 ? 4 : 2;
}

std::vector<Derived::ConstraintPass> Derived::constraint_schedule(int passes) const {
  // A lone pass runs as a pair's first does, smoothed and as bold, where lambda is smoothed:
  // the coarse correction (at COARSE_LONE_STRENGTH) takes the long modes, which a second pass
  // would otherwise have to (docs/physics.md). Unsmoothed it runs at the single pass's gain.
  if (passes == 1 && smooths_lambda())
    return {{jacobi_schedule(1, solver.jacobi_gain, paired_gain_max)[0], true}};
  std::vector<ConstraintPass> schedule;
  for (double w : jacobi_schedule(passes - passes % 2, solver.jacobi_gain, paired_gain_max))
    schedule.push_back({w, smooths_lambda()});
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
  c.poly6_scale = float(kernels::poly6_scale(h));
  c.spiky_grad_scale = float(kernels::spiky_grad_scale(h));
  c.ldc_k = float(ldc_k);
  c.relaxation = 1.0f;  // set per constraint pass
  return c;
}

}  // namespace pbflow
