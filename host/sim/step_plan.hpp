#pragma once
// One step of either solver, declared once: its passes in order and when each runs. GpuSolver
// records the plan, ReferenceSolver executes it, so the two cannot drift apart; adding a pass
// is a row here and a case in each solver (docs/design.md, "One step").
#include <vector>

#include "sim/params.hpp"
#include "sim/solver.hpp"

namespace pbflow {

enum class Pass {
  Density,            // rho at x, for LDC's force
  CorrectionPredict,  // LDC's force, then v += g dt and x* = x + v dt (one pass on the GPU)
  Predict,            // v += g dt, x* = x + v dt
  Grid,               // particles sorted into cells at x*
  Lists,              // each particle's neighbours at x* (the GPU's; the reference walks its cells)
  Lambda,             // a constraint iteration's lambda (and rho at x*)
  Coarse,             // the coarse correction of the long density modes, from the first lambda's rho
  Smooth,             // lambda averaged over the neighbours
  Apply,              // x* moved by the iteration's correction, at its under-relaxation
  Adaptive,           // iteration pairs while the mean compression is above the target
  Velocity,           // v = (x* - x) / dt, x = x*
  Viscosity,          // XSPH, the dashpot, and the vorticity's omega
  Vorticity,          // the vorticity confinement force
};

struct PlannedPass {
  Pass pass;
  PassGroup group;   // what the benchmarks' split counts it under
  double omega = 0;  // Apply: the iteration's under-relaxation ω
};

// An adaptive step's extra iterations come this many at a time: an Apply swaps two arrays'
// roles on the GPU's host side whether or not the GPU runs it, so only pairs keep x* in place.
inline constexpr int kAdaptiveStride = 2;

// A step. `density_current`: rho at x is already known (the GPU's viscosity pass leaves it).
std::vector<PlannedPass> step_plan(const Derived& d, bool density_current = false);
// `iterations` constraint iterations as Derived::constraint_schedule lays them out, the coarse
// correction beside the first where the scene runs it and `with_coarse` asks.
std::vector<PlannedPass> constraint_plan(const Derived& d, int iterations, bool with_coarse = true);
// The start-up projection (Solver::project), after x* = x: the grid and lists at x* and one
// constraint iteration, whatever the step runs.
std::vector<PlannedPass> projection_plan(const Derived& d);

}  // namespace pbflow
