#include "sim/frame_plan.hpp"

namespace pbflow {

std::vector<PlannedPass> constraint_plan(const Derived& d, int iterations, bool with_coarse) {
  std::vector<PlannedPass> plan;
  for (const Derived::ConstraintPass& pass : d.constraint_schedule(iterations)) {
    plan.push_back({Pass::Lambda, PassGroup::Constraints});
    if (with_coarse && plan.size() == 1 && d.coarse.strength > 0) plan.push_back({Pass::Coarse, PassGroup::Coarse});
    if (pass.smoothed) plan.push_back({Pass::Smooth, PassGroup::Constraints});
    plan.push_back({Pass::Apply, PassGroup::Constraints, pass.relaxation});
  }
  return plan;
}

namespace {
void append(std::vector<PlannedPass>& plan, const std::vector<PlannedPass>& more) {
  plan.insert(plan.end(), more.begin(), more.end());
}
const std::vector<PlannedPass> kGridAndLists = {{Pass::Grid, PassGroup::Grid}, {Pass::Lists, PassGroup::Lists}};
}  // namespace

std::vector<PlannedPass> step_plan(const Derived& d) {
  const SolverParams& p = d.solver;
  std::vector<PlannedPass> plan;
  // The solids move before the prediction, which meets them where the step ends.
  if (p.method == Method::Ldc) {
    plan.push_back({Pass::Density, PassGroup::Density});
    if (d.moving()) plan.push_back({Pass::Move, PassGroup::Correction});
    plan.push_back({Pass::CorrectionPredict, PassGroup::Correction});
  } else {
    if (d.moving()) plan.push_back({Pass::Move, PassGroup::Predict});
    plan.push_back({Pass::Predict, PassGroup::Predict});
  }
  append(plan, kGridAndLists);
  append(plan, constraint_plan(d, p.iterations));
  if (p.target_compression > 0) plan.push_back({Pass::Adaptive, PassGroup::Constraints});
  plan.push_back({Pass::Velocity, PassGroup::Velocity});
  if (p.viscosity_pass()) plan.push_back({Pass::Viscosity, PassGroup::Viscosity});
  if (p.vorticity > 0) plan.push_back({Pass::Vorticity, PassGroup::Viscosity});
  return plan;
}

std::vector<PlannedPass> frame_plan(const Derived& d, int steps, FrameOutputs outputs) {
  std::vector<PlannedPass> plan;
  const std::vector<PlannedPass> step = step_plan(d);
  for (int k = 0; k < steps; ++k) {
    append(plan, step);
    plan.push_back({Pass::Watch, step.back().group});  // timed with the step's last group
  }
  plan.push_back({Pass::Density, PassGroup::Measures});
  plan.push_back({Pass::Measures, PassGroup::Measures});
  if (outputs.surface) plan.push_back({Pass::Surface, PassGroup::Surface});
  if (outputs.white_water)
    append(plan, {{Pass::WhiteWaterAdvect, PassGroup::WhiteWater}, {Pass::WhiteWaterEmit, PassGroup::WhiteWater}});
  return plan;
}

std::vector<PlannedPass> relaxation_plan(const Derived& d) {
  std::vector<PlannedPass> plan = kGridAndLists;
  append(plan, constraint_plan(d, 1));
  return plan;
}

}  // namespace pbflow
