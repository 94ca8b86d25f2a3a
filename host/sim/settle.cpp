#include "sim/settle.hpp"

#include <cmath>
#include <deque>

namespace pbflow {

namespace {
constexpr double kMomentum = 0.8;  // ~(1 - sqrt(mu))^2 for the column's slow mode, mu ~ 0.01-0.02
constexpr int kMinSteps = 50, kMaxSteps = 1000;
constexpr int kWindow = 25;         // steps over which the potential energy must stand still
constexpr double kStill = 2e-4;     // relative change of the potential energy over the window
}  // namespace

void relax_start(Solver& solver, const std::function<bool(int)>& progress) {
  for (int k = 1; k <= kStartRelaxations; ++k) {
    solver.relax();
    if (progress && !progress(k)) return;
  }
}

SettleReport settle(Solver& solver, const Derived& d, const std::function<bool(int)>& progress) {
  SettleReport report;
  const double g = glm::length(d.gravity);
  if (g == 0) return report;  // nothing pulls the fluid anywhere: the lattice is the equilibrium
  const glm::dvec3 down = d.gravity / g;
  auto along = [&](const glm::dvec3& a) { return glm::dot(a, down) * down; };
  auto whole = [](const glm::dvec3& a) { return a; };

  solver.hold_solids(true);  // the fluid comes to rest around the solids where they start
  ParticleState state = solver.download();
  const double start = solver.advance(0).potential_energy;
  double potential = start;
  // Runs `step` (one step, returning its potential energy) until the potential energy
  // stands still; false when stopped by `progress` or kMaxSteps.
  auto until_still = [&](auto step) {
    std::deque<double> window{potential};
    for (int steps = 0; steps < kMaxSteps; ++steps) {
      potential = step();
      ++report.steps;
      window.push_back(potential);
      if (window.size() > kWindow + 1) window.pop_front();
      if (progress && !progress(report.steps)) return false;
      if (steps + 1 >= kMinSteps && std::abs(window.back() - window.front()) <= kStill * std::abs(window.back()))
        return true;
    }
    return false;
  };
  // A scene step followed by `keep` on every particle's move and velocity (heavy-ball damped).
  auto held = [&](auto keep) {
    return [&, keep] {
      FrameStats s = solver.advance(1);
      ParticleState now = solver.download();
      for (size_t i = 0; i < now.x.size(); ++i) {
        now.x[i] = state.x[i] + keep(now.x[i] - state.x[i]);
        now.v[i] = kMomentum * keep(now.v[i]);
      }
      now.x_pred = now.x;
      solver.upload(now);
      state = std::move(now);
      return s.potential_energy;
    };
  };
  // First the column settles as in a container, along gravity only (nothing flows
  // sideways, the lattice keeps its columns); then free, so that a lattice squeezed past
  // what it holds in 3-D rearranges here, damped, and not after frame 0. Last the scene's
  // own steps, undamped: the damped fluid sits a little denser than the moving one.
  report.converged = until_still(held(along)) && until_still(held(whole)) &&
                     until_still([&] { return solver.advance(1).potential_energy; });
  state = solver.download();
  for (glm::dvec3& v : state.v) v = glm::dvec3(0.0);
  solver.upload(state);
  solver.hold_solids(false);
  report.potential_drop = start - potential;
  return report;
}

}  // namespace pbflow
