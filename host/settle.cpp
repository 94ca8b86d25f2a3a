#include "settle.hpp"

#include <cmath>
#include <deque>

namespace pbflow {

namespace {
constexpr double kMomentum = 0.8;  // ~(1 - sqrt(mu))^2 for the column's slow mode, mu ~ 0.01-0.02
constexpr int kMinSteps = 50, kMaxSteps = 1000;
constexpr int kWindow = 25;         // steps over which the potential energy must stand still
constexpr double kStill = 2e-4;     // relative change of the potential energy over the window
}  // namespace

SettleReport settle(Solver& solver, const Derived& d, const std::function<bool(int)>& progress) {
  SettleReport report;
  const double g = glm::length(d.gravity);
  if (g == 0) return report;  // nothing pulls the fluid anywhere: the lattice is the equilibrium
  const glm::dvec3 down = d.gravity / g;
  auto along = [&](const glm::dvec3& a) { return glm::dot(a, down) * down; };

  ParticleState before = solver.download();
  std::deque<double> potential{solver.advance(0).potential_energy};
  const double start = potential.front();
  while (report.steps < kMaxSteps) {
    FrameStats s = solver.advance(1);
    ParticleState now = solver.download();
    for (size_t i = 0; i < now.x.size(); ++i) {
      now.x[i] = before.x[i] + along(now.x[i] - before.x[i]);
      now.v[i] = kMomentum * along(now.v[i]);
    }
    now.x_pred = now.x;
    solver.upload(now);
    before = std::move(now);
    ++report.steps;
    potential.push_back(s.potential_energy);
    if (potential.size() > kWindow + 1) potential.pop_front();
    if (progress && !progress(report.steps)) break;
    if (report.steps >= kMinSteps && std::abs(potential.back() - potential.front()) <= kStill * std::abs(potential.back())) {
      report.converged = true;
      break;
    }
  }
  for (glm::dvec3& v : before.v) v = glm::dvec3(0.0);
  solver.upload(before);
  report.potential_drop = start - potential.back();
  return report;
}

}  // namespace pbflow
