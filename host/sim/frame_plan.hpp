#pragma once
// One frame of either solver, declared once: its steps' passes in order, the divergence watch
// after each step, the measures, then each output the frame was asked for. GpuSolver records
// the plan, ReferenceSolver executes it, so the two cannot drift apart; adding a pass is a row
// here and a case in each solver (docs/design.md, "One frame").
#include <vector>

#include "sim/params.hpp"
#include "sim/solver.hpp"

namespace pbflow {

enum class Pass {
  // A step's passes.
  Move,               // the moving solids to their poses at the step's end (Derived::move_solids)
  Density,            // rho at x, for LDC's force (skipped where a pass left it current)
  CorrectionPredict,  // LDC's force, then v += g dt and x* = x + v dt (one pass on the GPU)
  Predict,            // v += g dt, x* = x + v dt
  Grid,               // particles sorted into cells at x*
  Lists,              // each particle's neighbours at x* (the GPU's; the reference walks its cells)
  Lambda,             // a constraint iteration's lambda (and rho at x*)
  Coarse,             // the coarse correction of the long density modes, from the first lambda's rho
  Smooth,             // lambda averaged over the neighbours
  Apply,              // x* moved by the iteration's correction, at its relaxation
  Adaptive,           // iteration pairs while the mean compression is above the target
  Velocity,           // v = (x* - x) / dt, x = x*
  Viscosity,          // XSPH, the dashpot, and the vorticity's curl
  Vorticity,          // the vorticity confinement force
  Watch,              // the divergence watch, after each step
  // The frame's end: the measures, then the outputs (FrameOutputs).
  Measures,           // the reductions of docs/design.md's measures, from rho at x
  Surface,            // smoothed positions and drawn shapes, from the last lists
  WhiteWaterAdvect,   // the living white water moved, aged and retyped
  WhiteWaterEmit,     // the fluid's births appended
};

struct PlannedPass {
  Pass pass;
  PassGroup group;         // what the benchmarks' split counts it under
  double relaxation = 0;   // Apply: the iteration's under-relaxation
};

// An adaptive step's extra iterations come this many at a time: an Apply swaps two arrays'
// roles on the GPU's host side whether or not the GPU runs it, so only pairs keep x* in place.
inline constexpr int kAdaptiveStride = 2;

// Of the outputs asked for, those the scene makes: white water only where it enables it.
inline FrameOutputs outputs_made(const Derived& d, FrameOutputs asked) {
  return {asked.surface, asked.white_water && d.white_capacity() > 0};
}
// A frame of `steps` steps (0: the measures and outputs alone) and `outputs` (outputs_made's).
std::vector<PlannedPass> frame_plan(const Derived& d, int steps, FrameOutputs outputs);
// One step, without its watch.
std::vector<PlannedPass> step_plan(const Derived& d);
// `iterations` constraint iterations as Derived::constraint_schedule lays them out, the coarse
// correction beside the first where the scene runs it and `with_coarse` asks.
std::vector<PlannedPass> constraint_plan(const Derived& d, int iterations, bool with_coarse = true);
// The start-up relaxation (Solver::relax_start), after x* = x: the grid and lists at x* and one
// constraint iteration, whatever the step runs.
std::vector<PlannedPass> relaxation_plan(const Derived& d);

}  // namespace pbflow
