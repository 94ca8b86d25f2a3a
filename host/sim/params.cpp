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
  // Two averages cut a pass's worst gain from 2.79 to 0.99, so a pair runs 2.8x bolder:
  // 2.4-3.4x less compression at 2-4 iterations, for two more list passes an iteration.
  // Four cut it to 0.61 (1.6x bolder again). An average costs ~0.4x a lambda or dp pass
  // (peer scene), so in time four reach a compression sooner than more iterations with
  // two: pbf@3 with four 0.86-1.04x the time of pbf@4 with two, pbf@4 with four 0.79-0.97x
  // pbf@6 with two, for the same compression (docs/physics.md). But the pairs' boldness rests on
  // the lattice model, which assumes a step moves less than h: at 1.35 and 1.85 h per
  // step, four averages made 4.8-7.7 % energy where two made none; at 0.67-0.92 h every
  // setting measured was sound. Two iterations keep two: the real-time setting that meets
  // its accuracy (the peer's pbf@2 figure) at the least cost per step.
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
