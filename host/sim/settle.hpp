#pragma once
// A scene that starts at rest ("settle": true) starts in the solver's own equilibrium.
//
// Why: a lattice at rho0 is not at rest for a solver that holds the density only
// approximately, so a tank released from the lattice falls and then breathes: its slowest
// mode is damped by only ~mu/2 per step. Weakly compressible SPH codes start such a tank
// with its hydrostatic density for the same reason; here the equilibrium depends on the
// method, the iterations and the step, so the solver finds it itself.
//
// How: the scene's own steps, each followed by a hold: every particle keeps only the part
// of its move along gravity (the column settles as in a container, nothing flows
// sideways) and its velocity, also along gravity, is damped by kMomentum (a heavy ball,
// which converges in ~1/sqrt(mu) steps instead of the ~1/mu of a pure damping), until the
// potential energy has stopped changing; then the same with the whole move kept; last the
// scene's own steps, undamped, until it stands still again (the damped fluid sits a little
// denser than the moving one). The velocities are then zero.
#include <functional>

#include "sim/params.hpp"
#include "sim/solver.hpp"

namespace pbflow {

// Every run starts relaxed: the start's jitter (scene/seeding.hpp) brings some particles closer
// than the lattice, and released from there the solver would push them apart and lift the
// fluid. kStartRelaxations relaxations (Solver::relax) keep the energy tests' bound
// (docs/physics.md, "The start").
inline constexpr int kStartRelaxations = 40;
// `progress(relaxation)`, if given, is called after each relaxation; false stops early (an
// interrupt). They cost about forty single-iteration steps.
void relax_start(Solver& solver, const std::function<bool(int)>& progress = {});

struct SettleReport {
  int steps = 0;
  bool converged = false;  // false: stopped at kMaxSteps
  double potential_drop = 0;  // J: how far the fluid sank into its equilibrium
};

// Runs on any solver (GPU or reference). `progress(step)`, if given, is called after every
// step; it returns false to stop early (an interrupt).
SettleReport settle(Solver& solver, const Derived& d, const std::function<bool(int)>& progress = {});

}  // namespace pbflow
