#include "sim/reference_solver.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <utility>

#include "shaders/contract.h"
#include "sim/kernels.hpp"
#include "sim/stability.hpp"

namespace pbflow {

using glm::dvec3;

ReferenceSolver::ReferenceSolver(const Derived& d, const std::vector<dvec3>& x0) : d_(d) {
  size_t n = x0.size();
  state.x = x0;
  state.v.assign(n, dvec3(0.0));
  state.x_pred = x0;
  state.curl.assign(n, dvec3(0.0));
  state.rho.assign(n, 0.0);
  state.lambda.assign(n, 0.0);
  state.id.resize(n);
  std::iota(state.id.begin(), state.id.end(), 0u);
  capacity_ = d.capacity_for(n);
  next_id_ = uint32_t(n);
  cells_.resize(size_t(d.grid.x) * d.grid.y * d.grid.z);
  bodies_ = BodyCoupling(d.bodies.size());
}

void ReferenceSolver::upload(const ParticleState& s) {
  if (s.x.size() > capacity_) throw std::invalid_argument("upload: more particles than the solver's capacity");
  state.x = s.x;
  state.v = s.v;
  state.x_pred = s.x_pred;
  // rho as GpuSolver::upload takes it (0 where s has none): the dashpot's until a step measures it.
  state.rho.assign(state.x.size(), 0.0);
  std::copy_n(s.rho.begin(), std::min(s.rho.size(), state.rho.size()), state.rho.begin());
  // The passes' own arrays at the new count (a live run carries more particles than it started with).
  state.curl.assign(state.x.size(), dvec3(0.0));
  state.lambda.assign(state.x.size(), 0.0);
  state.id = s.id;
  if (state.id.empty()) {
    state.id.resize(state.x.size());
    std::iota(state.id.begin(), state.id.end(), 0u);
  }
  if (!state.id.empty()) next_id_ = std::max(next_id_, state.id.back() + 1);
  neighbours_built_ = false;
  coarse_phi_.clear();
  drawn = {};
}

void ReferenceSolver::carry(const SolidsState& s) {
  carry_clocks(s, d_.dt);
  d_.carry_solids(s.obstacles, s.tank, s.bodies);
}

glm::ivec3 ReferenceSolver::cell_of(const dvec3& x) const {
  dvec3 c = glm::floor((x - d_.domain_min) / d_.h);
  glm::ivec3 cell(0);  // a NaN coordinate (a diverged particle) goes to cell 0; the watch reports it
  for (int k = 0; k < 3; ++k)
    if (c[k] == c[k]) cell[k] = int(std::clamp(c[k], 0.0, double(d_.grid[k] - 1)));
  return cell;
}

void ReferenceSolver::build_neighbours(const std::vector<dvec3>& at) {
  // As the GPU's lists: `capacity` entries a particle and a count, which past the capacity
  // marks the list overflowed (its entries are then not kept: the passes walk the cells).
  // Bounded, so that the memory estimate is exact whatever the compression.
  const size_t capacity = d_.neighbour_capacity;
  neighbour_count_.assign(at.size(), 0);
  neighbour_list_.resize(at.size() * capacity);
  creases_.assign(at.size(), Creases{});
  for (size_t i = 0; i < at.size(); ++i) {
    Neighbour* list = neighbour_list_.data() + i * capacity;
    uint32_t count = 0;
    auto add = [&](size_t j, uint32_t image) {
      if (count < capacity) list[count] = {uint32_t(j), image};
      ++count;
    };
    for_each_candidate(at[i], [&](size_t j) {
      dvec3 d = at[i] - at[j];
      if (glm::dot(d, d) < d_.h * d_.h) add(j, 0);
    });
    // An image lies farther than its particle: only the neighbours' can be within h.
    Mirrors mirrors = mirrors_near(d_, at[i]);
    creases_[i] = find_creases(d_, mirrors);
    mirrors.take(creases_[i]);
    for (uint32_t n = count, k = 0; n <= capacity && k < n; ++k)
      for (int image = 1; image < kImages; ++image) {  // past the neighbour itself
        if ((image & mirrors.axes) != image) continue;
        dvec3 d = at[i] - mirrors.of(image, at[list[k].j]);
        if (glm::dot(d, d) < d_.h * d_.h) add(list[k].j, uint32_t(image));
      }
    neighbour_count_[i] = count;
  }
  neighbours_current_ = neighbours_built_ = true;
  moved_since_lists_ = false;
}

void ReferenceSolver::build_grid(const std::vector<dvec3>& at) {
  for (auto& cell : cells_) cell.clear();
  for (size_t i = 0; i < at.size(); ++i) cells_[cell_id(cell_of(at[i]))].push_back(i);
  neighbours_current_ = false;
}

void ReferenceSolver::density() {
  if (!neighbours_current_) build_neighbours(state.x);  // else the last step's, built at its x_pred
  for (size_t i = 0; i < state.x.size(); ++i) {
    double sum = 0;
    for_each_neighbour(i, state.x[i], [&](size_t j, const Image& m) {
      dvec3 d = state.x[i] - m.of(state.x[j]);
      sum += kernels::poly6(glm::dot(d, d), d_.h);
    });
    state.rho[i] = d_.mass * sum;
  }
}

dvec3 ReferenceSolver::correction_force(size_t i, double* work) const {
  auto rho = [&](size_t k) { return d_.solver.ldc_clamp ? std::max(state.rho[k], d_.rho0) : state.rho[k]; };
  const dvec3 xi = state.x[i];
  // correction_force.comp says why K is capped in squeezed fluid.
  const double squeeze = std::max(state.rho[i], d_.rho0) / d_.rho0;
  const double k = -d_.ldc_k * std::min(1.0, d_.ldc_room / (squeeze * squeeze));
  // f = sum_j (rho_j - rho_i) h (1 - r/h) d/r
  dvec3 f(0.0);
  for_each_neighbour(i, xi, [&](size_t j, const Image& m) {
    const double difference = (rho(j) - rho(i)) / d_.rho0;
    dvec3 d = m.of(state.x[j]) - xi;
    double r = glm::length(d);
    if (r <= 0 || r >= d_.h) return;
    const dvec3 term = difference * d_.h * (1 - r / d_.h) * (d / r);
    f += term;
    if (work && m.mirrors->solid(m.k) && !push_body(m.mirrors->obstacle.body, xi, k * term * d_.dt * d_.dt))
      *work += glm::dot(k * term, m.mirrors->solid_velocity) * d_.dt;
  });
  return k * f;
}

void ReferenceSolver::correction() {
  std::vector<dvec3> f(state.x.size());
  for (size_t i = 0; i < f.size(); ++i) f[i] = correction_force(i, &solid_work_);
  for (size_t i = 0; i < f.size(); ++i) state.v[i] += f[i] * d_.dt;  // predict() adds g and the kick
}

// A particle this close to an obstacle (a fraction of h) touches it (solids.glsl too).
constexpr double kContact = 1e-3;

void ReferenceSolver::predict() {
  for (size_t i = 0; i < state.x.size(); ++i) {
    const glm::dvec3 kick = d_.tank_kick.at(state.x[i], state.v[i]);
    state.v[i] += d_.gravity * d_.dt + kick;
    state.x_pred[i] = move_outside_solids(state.x[i], state.x[i] + state.v[i] * d_.dt, solid_work_);
  }
}

dvec3 ReferenceSolver::move_outside_solids(const dvec3& from, dvec3 to, double& work) const {
  // Each obstacle can only shorten the move, so the last shortening is the first entry.
  for (const Obstacle& o : d_.obstacles) {
    const dvec3 stopped = stop_at(o, from, to, kContact * d_.h, d_.keep_out);
    if (stopped != to && !push_body(o.body, stopped, stopped - to))
      work += push_work(stopped - to, o.displacement(stopped), d_.dt);
    to = stopped;
  }
  return project_out_of_solids(to, work);
}

void ReferenceSolver::constraint_lambda() {
  if (!neighbours_current_) build_neighbours(state.x_pred);  // the first pass after the grid build
  const double s = d_.mass / d_.rho0;
  for (size_t i = 0; i < state.x.size(); ++i) {
    const dvec3 xi = state.x_pred[i];
    double w_sum = 0, grad_sq = 0;
    dvec3 own(0.0);  // grad_i C_i
    // A neighbour's image is a neighbour of its own, its term squared on its own; i's own
    // images move with i and count twice in grad_i C_i (constraint_lambda.comp says why).
    for_each_neighbour(i, xi, [&](size_t j, const Image& m) {
      dvec3 d = xi - m.of(state.x_pred[j]);
      w_sum += kernels::poly6(glm::dot(d, d), d_.h);
      dvec3 grad = s * kernels::spiky_grad(d, d_.h);
      if (j == i) {
        own += 2.0 * grad;
        return;
      }
      own += grad;
      grad_sq += glm::dot(grad, grad);
    });
    double rho = d_.mass * w_sum;
    double c = std::max(rho / d_.rho0 - 1.0, 0.0);
    state.lambda[i] = -c / ((grad_sq + glm::dot(own, own) + d_.epsilon) * (1.0 + kCompressedGain * c));  // constraint_lambda.comp
    state.rho[i] = rho;  // kept for the adaptive iterations' check
  }
}

void ReferenceSolver::constraint_smooth() {
  for (int pass = 0; pass < d_.solver.lambda_smoothing; ++pass) {
    std::vector<double> mean(state.x.size());
    for (size_t i = 0; i < mean.size(); ++i) {
      const dvec3 xi = state.x_pred[i];
      double total = 0;
      for_each_neighbour(i, xi, [&](size_t j, const Image& m) {  // an image carries j's lambda
        const double w = kernels::smoothing_weight(xi - m.of(state.x_pred[j]), d_.h);
        mean[i] += w * state.lambda[j];
        total += w;
      });
      mean[i] /= total;
    }
    state.lambda = std::move(mean);
  }
}

void ReferenceSolver::constraint_apply(double relaxation) {
  std::vector<dvec3> next(state.x.size());
  for (size_t i = 0; i < next.size(); ++i) {
    const dvec3 xi = state.x_pred[i];
    dvec3 dp(0.0);
    const double scale = relaxation * (d_.mass / d_.rho0);
    // An image carries its particle's lambda; i's own images push i away from the wall.
    for_each_neighbour(i, xi, [&](size_t j, const Image& m) {
      dvec3 d = xi - m.of(state.x_pred[j]);
      const dvec3 term = (state.lambda[i] + state.lambda[j]) * kernels::spiky_grad(d, d_.h);
      dp += term;
      if (m.mirrors->solid(m.k) && !push_body(m.mirrors->obstacle.body, xi, scale * term))
        solid_work_ += push_work(scale * term, m.mirrors->solid_velocity * d_.dt, d_.dt);
    });
    next[i] = project_out_of_solids(xi + scale * dp, solid_work_);
  }
  state.x_pred = std::move(next);
}

namespace {
// The walls a particle at x touches (within a quarter of h), as coarse_deposit.comp's bits.
uint32_t walls_touched(const Derived& d, const glm::dvec3& x) {
  uint32_t touched = 0;
  for (int a = 0; a < 3; ++a) {
    if (x[a] - d.wall_min[a] < 0.25 * d.h) touched |= 1u << (2 * a);
    if (d.wall_max[a] - x[a] < 0.25 * d.h) touched |= 2u << (2 * a);
  }
  return touched;
}

// A node's flags (coarse_prepare.comp): COARSE_FLUID, and air past each wall above the node that
// it borders and none of the particles nearest it touches, where its deposit makes it fluid and
// no solid is in its reach.
uint32_t coarse_flags(const Derived::Coarse& c, const glm::dvec3& gravity, int k, bool deposited, uint32_t touched) {
  if (!deposited && c.open[k] >= COARSE_FILL) return 0;
  uint32_t flags = COARSE_FLUID;
  if (!deposited || c.open[k] <= 1 - COARSE_FILL) return flags;
  const glm::ivec3 p = c.node(k);
  const glm::dvec3 up = glm::length(gravity) > 0 ? -glm::normalize(gravity) : glm::dvec3(0.0);
  for (int a = 0; a < 3; ++a) {
    if (p[a] == 0 && -up[a] > COARSE_UP && !(touched & (1u << (2 * a)))) flags |= COARSE_AIR_PAST << (2 * a);
    if (p[a] == c.nodes[a] - 1 && up[a] > COARSE_UP && !(touched & (2u << (2 * a)))) flags |= COARSE_AIR_PAST << (2 * a + 1);
  }
  return flags;
}

// The fluid nodes' mean right-hand side where no node has air, else 0 (contract.h,
// COARSE_TOTALS; coarse_sweep.comp's mean_source, its float sum of the fixed-point excess).
double mean_source(const std::vector<uint32_t>& flags, const std::vector<uint32_t>& excess, double per_unit) {
  uint64_t fluid = 0, total = 0;
  for (size_t k = 0; k < flags.size(); ++k) {
    if (flags[k] != COARSE_FLUID) return 0;  // air, or air past a wall
    ++fluid, total += excess[k];
  }
  return fluid ? double(float(total) / float(fluid) / float(COARSE_UNIT) * float(per_unit)) : 0.0;
}
}  // namespace

// As coarse_deposit, coarse_prepare and coarse_sweep.comp, in their order and fixed-point sums:
// phi on the coarse grid, into coarse_phi_; each node's flags.
std::vector<uint32_t> ReferenceSolver::coarse_solve() {
  const Derived::Coarse& c = d_.coarse;
  const int count = c.count();
  std::vector<uint32_t> filled(count, 0), excess(count, 0), touched(count, 0);
  for (size_t i = 0; i < state.x.size(); ++i) {
    const double compression = std::clamp(state.rho[i] / d_.rho0 - 1.0 - COARSE_FLOOR, 0.0, COARSE_MAX_COMPRESSION);
    for_each_coarse_node(d_, state.x_pred[i], [&](int k, double w) {
      filled[k] += uint32_t(w * COARSE_UNIT + 0.5);
      excess[k] += uint32_t(w * compression * COARSE_UNIT + 0.5);
    });
    touched[coarse_node_at(d_, state.x_pred[i])] |= walls_touched(d_, state.x_pred[i]);
  }
  // grad^2 phi = the excess volume per volume, phi = 0 at nodes without fluid (a node a solid
  // fills counts as fluid at rest), no flux through the walls but past a lid the water does not
  // touch (air): x_pred moves along grad phi, away from the compressed fluid.
  const double volume = d_.mass / d_.rho0, cell_volume = c.cell.x * c.cell.y * c.cell.z;
  std::vector<uint32_t> flags(count);
  std::vector<double>& phi = coarse_phi_;  // from the last step's (coarse_sweep.comp says why)
  phi.resize(count, 0.0);
  for (int k = 0; k < count; ++k) {
    flags[k] = coarse_flags(c, d_.gravity, k, filled[k] / COARSE_UNIT * volume > COARSE_FILL * c.open[k] * cell_volume, touched[k]);
    if (!flags[k]) phi[k] = 0.0;
  }
  const glm::ivec3 n = c.nodes;
  const double mean = mean_source(flags, excess, volume / cell_volume);
  auto value = [&](glm::ivec3 p) { return phi[c.index(p)]; };  // 0 at nodes without fluid
  const int longest = std::max({n.x, n.y, n.z});  // coarse.glsl's coarse_overrelaxation
  const double overrelaxation = 2.0 / (1.0 + std::sin(std::numbers::pi / (2.0 * longest)));
  for (int sweep = 0; sweep < COARSE_SWEEPS; ++sweep)
    for (int colour = 0; colour < 2; ++colour)
      for (int k = 0; k < count; ++k) {
        const glm::ivec3 p = c.node(k);
        if (!flags[k] || (p.x + p.y + p.z) % 2 != colour) continue;
        double sum = 0, weights = 0;  // each neighbour weighed by 1 / (its axis's cell)^2
        for (int a = 0; a < 3; ++a) {
          const double w = 1.0 / (c.cell[a] * c.cell[a]);
          for (int side = 0; side < 2; ++side) {
            glm::ivec3 q = p;
            q[a] += 2 * side - 1;
            const bool past = q[a] < 0 || q[a] >= n[a];  // a wall: no flux, or air (0)
            if (past && !(flags[k] & (COARSE_AIR_PAST << (2 * a + side)))) continue;
            if (!past) sum += w * value(q);
            weights += w;
          }
        }
        if (weights > 0) {
          const double gauss_seidel = (sum - (double(float(excess[k] / COARSE_UNIT * volume / cell_volume)) - mean)) / weights;
          phi[k] += overrelaxation * (gauss_seidel - phi[k]);
        }
      }
  return flags;
}

// Then as coarse_gradient and coarse_apply.comp: x_pred moved along grad phi.
void ReferenceSolver::coarse_correction() {
  const Derived::Coarse& c = d_.coarse;
  const std::vector<double>& phi = coarse_phi_;
  const std::vector<dvec3> grad = coarse_gradient(coarse_solve());
  add_buoyancy(grad);
  for (size_t i = 0; i < state.x.size(); ++i) {
    dvec3 g(0.0);
    double p = 0;
    for_each_coarse_node(d_, state.x_pred[i], [&](int k, double w) { g += w * grad[k], p += w * phi[k]; });
    // phi is a pressure: on a particle of a moving solid's first layer, its reaction on the
    // face it stands for (a spacing squared) is worked by the solid (coarse_apply.comp).
    dvec3 normal, velocity;
    if (d_.nearest_moving_solid(state.x_pred[i], normal, velocity) < d_.spacing)
      solid_work_ += -d_.rho0 * c.strength * p * glm::dot(normal, velocity) * d_.spacing * d_.spacing / (d_.dt * d_.mass);
    state.x_pred[i] = project_out_of_solids(state.x_pred[i] + c.strength * g, solid_work_);
  }
}

// grad phi at each fluid node, central differences, one-sided at the walls, against 0 where air
// lies past one (coarse_gradient.comp).
std::vector<dvec3> ReferenceSolver::coarse_gradient(const std::vector<uint32_t>& flags) const {
  const Derived::Coarse& c = d_.coarse;
  const std::vector<double>& phi = coarse_phi_;
  std::vector<dvec3> grad(c.count(), dvec3(0.0));
  for (int k = 0; k < c.count(); ++k) {
    if (!flags[k]) continue;
    const glm::ivec3 p = c.node(k);
    for (int a = 0; a < 3; ++a) {
      glm::ivec3 lo = p, hi = p;
      lo[a] -= 1;
      hi[a] += 1;
      auto wall = [&](int side) { return flags[k] & (COARSE_AIR_PAST << (2 * a + side)) ? 0.0 : phi[k]; };
      const double below = lo[a] >= 0 ? phi[c.index(lo)] : wall(0), above = hi[a] < c.nodes[a] ? phi[c.index(hi)] : wall(1);
      grad[k][a] = (above - below) / (2 * c.cell[a]);
    }
  }
  return grad;
}

void ReferenceSolver::velocity_update() {
  const bool kicked = !d_.tank_kick.none();
  for (size_t i = 0; i < state.x.size(); ++i) {
    // The tank's motion's work, in its frame: its kick times the particle's move over the step,
    // as gravity's is (the predicted move, which the constraint may take back, credited water at
    // rest in a held tilt with work it never did).
    const glm::dvec3 kick = kicked ? d_.tank_kick.taken(state.x[i], state.v[i], d_.gravity, d_.dt) : glm::dvec3(0.0);
    state.v[i] = (state.x_pred[i] - state.x[i]) / d_.dt;
    solid_work_ += glm::dot(kick, state.v[i]);
    state.x[i] = state.x_pred[i];
  }
}

void ReferenceSolver::viscosity_vorticity() {
  const double volume = d_.mass / d_.rho0;
  std::vector<dvec3> v_next(state.x.size());
  for (size_t i = 0; i < v_next.size(); ++i) {
    dvec3 smooth(0.0), curl(0.0), damp(0.0);  // viscosity_vorticity.comp says what each is
    const double rho_i = std::max(state.rho[i], d_.rho0);
    for_each_neighbour(i, state.x[i], [&](size_t j, const Image& m) {
      const dvec3 d = state.x[i] - m.of(state.x[j]);
      const dvec3 vij = m.velocity(state.v[j]) - state.v[i];  // an image moves as j, mirrored
      const double r2 = glm::dot(d, d);
      if (m.k == 0) {  // XSPH and the vorticity see the fluid only
        smooth += vij * kernels::poly6(r2, d_.h);
        curl += glm::cross(vij, kernels::spiky_grad(d, d_.h));
      }
      const double c = std::min(d_.solver.damping, d_.damping_limit * d_.rho0 / std::max(rho_i, state.rho[j]));
      if (r2 <= 0 || r2 >= d_.h * d_.h) return;
      const dvec3 pushed = c * (1 - std::sqrt(r2) / d_.h) * glm::dot(vij, d) / r2 * d +
                           NO_SLIP_GAIN * volume * kernels::poly6(r2, d_.h) * m.mirrors->stick(m.k, state.v[i], state.v[j]);
      damp += pushed;
      if (m.mirrors->solid(m.k) && !push_body(m.mirrors->obstacle.body, state.x[i], pushed))  // the images' drag
        solid_work_ += glm::dot(pushed, m.mirrors->solid_velocity);
    });
    v_next[i] = state.v[i] + d_.solver.xsph * volume * smooth + damp;
    state.curl[i] = volume * curl;
  }
  state.v = std::move(v_next);
}

void ReferenceSolver::vorticity_force() {
  for (size_t i = 0; i < state.x.size(); ++i) {
    dvec3 eta(0.0);
    for_each_neighbour(i, state.x[i], [&](size_t j, const Image& m) {
      if (m.k == 0) eta += glm::length(state.curl[j]) * kernels::spiky_grad_shape(state.x[i] - state.x[j], d_.h);
    });
    double len = glm::length(eta);  // only its direction is used
    if (len > 0) state.v[i] += (d_.solver.vorticity * d_.dt / len) * glm::cross(eta, state.curl[i]);
  }
}

void ReferenceSolver::relax() {
  state.x_pred = state.x;
  const bool held = std::exchange(solids_held_, true);  // no time passes: the bodies stay
  for (const PlannedPass& pass : relaxation_plan(d_)) run(pass);
  solids_held_ = held;
  state.x = state.x_pred;
  for (dvec3& v : state.v) v = dvec3(0.0);
}

void ReferenceSolver::run(const PlannedPass& p) {
  switch (p.pass) {
    case Pass::Move:
      if (solids_held_)
        d_.hold_solids();
      else
        step_solids(d_, bodies_, double(++steps_moved_) * d_.dt);
      moved_since_lists_ = true;
      break;
    case Pass::Density: density_at_positions(); break;
    case Pass::CorrectionPredict: correction(), predict(), answer_bodies(false); break;
    case Pass::Predict: predict(), answer_bodies(false); break;
    case Pass::Grid: build_grid(state.x_pred); break;
    case Pass::Lists: break;  // the reference walks its cells
    case Pass::Lambda: constraint_lambda(); break;
    case Pass::Coarse: coarse_correction(), answer_bodies(false); break;
    case Pass::Smooth: constraint_smooth(); break;
    case Pass::Apply: constraint_apply(p.relaxation), answer_bodies(false); break;
    case Pass::Adaptive: adaptive_iterations(); break;
    case Pass::Velocity:
      velocity_update();
      if (!solids_held_) bodies_.finish(d_);
      break;
    case Pass::Viscosity: viscosity_vorticity(), answer_bodies(true); break;
    case Pass::Vorticity: vorticity_force(); break;
    case Pass::Watch: watch_step(step_in_frame_++, watch_); break;
    case Pass::Measures:
      measured_ = measure();
      measured_.solid_work = d_.mass * solid_work_ + bodies_.take_work();
      measured_.body_energy = BodyCoupling::energy(d_);
      break;
    case Pass::Surface: drawn = smoothed_positions(); break;
    case Pass::WhiteWaterAdvect: white_water_advect(frame_time_); break;
    case Pass::WhiteWaterEmit: white_water_emit(frame_time_, frames_advanced_); break;
  }
}

// As the GPU's check (check_converged.comp), from the last lambda pass's densities, a group
// of kAdaptiveStride iterations at a time (GpuSolver::adaptive_iterations).
void ReferenceSolver::adaptive_iterations() {
  const SolverParams& p = d_.solver;
  const std::vector<PlannedPass> group = constraint_plan(d_, kAdaptiveStride, false);
  for (int run = p.iterations; run + kAdaptiveStride <= p.max_iterations && mean_compression() > p.target_compression;
       run += kAdaptiveStride) {
    for (const PlannedPass& pass : group) this->run(pass);
    iterations_run_ += kAdaptiveStride;
  }
}

void ReferenceSolver::watch_step(int step, Divergence& watch) const {
  // As shaders/watch.comp: the first failing test per particle counts, at the first failing step.
  if (watch.first_step >= 0 && watch.first_step < step) return;
  for (size_t i = 0; i < state.x.size(); ++i) {
    const dvec3 &x = state.x[i], &v = state.v[i];
    bool finite = !glm::any(glm::isnan(x)) && !glm::any(glm::isinf(x)) && !glm::any(glm::isnan(v)) &&
                  !glm::any(glm::isinf(v));
    uint32_t* count = !finite                                ? &watch.not_finite
                      : glm::length(v) > d_.speed_limit      ? &watch.too_fast
                      : glm::any(glm::lessThan(x, d_.domain_min)) ||
                              glm::any(glm::greaterThan(x, d_.domain_max))
                          ? &watch.outside
                          : nullptr;
    if (!count) continue;
    ++*count;
    if (watch.first_step < 0) watch.first_step = step;
  }
}

double ReferenceSolver::mean_compression() const {
  double sum = 0;
  for (double rho : state.rho) sum += std::max(rho / d_.rho0 - 1.0, 0.0);
  return sum / double(std::max<size_t>(state.rho.size(), 1));
}

void ReferenceSolver::density_at_positions() {
  if (!neighbours_built_) build_grid(state.x);  // as the GPU: the last step's lists serve the density
  density();
}

FrameStats ReferenceSolver::measure() const {
  FrameStats s;
  const dvec3 lowest = d_.lowest();
  for (size_t i = 0; i < state.x.size(); ++i) {
    s.potential_energy += d_.mass * glm::dot(-d_.gravity, state.x[i] - lowest);
    double c = std::max(state.rho[i] / d_.rho0 - 1.0, 0.0);
    s.mean_compression += c;
    s.max_compression = std::max(s.max_compression, c);
    double v2 = glm::dot(state.v[i], state.v[i]);
    s.kinetic_energy += 0.5 * d_.mass * v2;
    s.max_speed = std::max(s.max_speed, std::sqrt(v2));
  }
  s.mean_compression /= double(std::max<size_t>(state.x.size(), 1));
  return s;
}

namespace {

// One Jacobi rotation in the (p, q) plane of a symmetric 3 x 3 matrix, r its third index
// (smoothed_positions.comp's jacobi_rotate, in double).
void jacobi_rotate(double& app, double& aqq, double& apq, double& arp, double& arq, dvec3& vp, dvec3& vq) {
  if (apq == 0.0) return;
  const double theta = 0.5 * (aqq - app) / apq;
  const double t = (theta >= 0.0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
  const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c, tau = s / (1.0 + c);
  app -= t * apq;
  aqq += t * apq;
  apq = 0.0;
  const double g = arp;
  arp -= s * (arq + tau * arp);
  arq += s * (g - tau * arq);
  const dvec3 w = vp;
  vp -= s * (vq + tau * vp);
  vq += s * (w - tau * vq);
}

// Jacobi sweeps diagonalise the symmetric c: c = v diag(l) v^T, v's columns unit eigenvectors.
void symmetric_eigen(const glm::dmat3& c, dvec3& l, glm::dmat3& v) {
  double d0 = c[0][0], d1 = c[1][1], d2 = c[2][2], o01 = c[1][0], o02 = c[2][0], o12 = c[2][1];
  dvec3 v0(1, 0, 0), v1(0, 1, 0), v2(0, 0, 1);
  for (int sweep = 0; sweep < SHAPE_SWEEPS; ++sweep) {
    jacobi_rotate(d0, d1, o01, o02, o12, v0, v1);
    jacobi_rotate(d0, d2, o02, o01, o12, v0, v2);
    jacobi_rotate(d1, d2, o12, o01, o02, v1, v2);
  }
  l = dvec3(d0, d1, d2);
  v = glm::dmat3(v0, v1, v2);
}

// A particle's drawn shape (the ellipsoid's matrix in radii, its longest semi-axis) from its
// neighbourhood's covariance and count (smoothed_positions.comp's write_shape).
std::pair<glm::dmat3, double> drawn_shape(const glm::dmat3& covariance, int count) {
  dvec3 l;
  glm::dmat3 axes;
  symmetric_eigen(covariance, l, axes);
  const double largest = std::max({l.x, l.y, l.z});
  if (count < SHAPE_MIN_NEIGHBOURS || !(largest > 0)) return {glm::dmat3(1.0), 1.0};
  dvec3 a = glm::max(l, dvec3(largest / SHAPE_MAX_STRETCH));
  a /= std::cbrt(a.x * a.y * a.z);  // the sphere's volume
  return {axes * glm::dmat3(a.x * a.x, 0, 0, 0, a.y * a.y, 0, 0, 0, a.z * a.z) * glm::transpose(axes),
          std::max({a.x, a.y, a.z})};
}

}  // namespace

ReferenceSolver::DrawnParticles ReferenceSolver::smoothed_positions() {
  if (!neighbours_current_) build_neighbours(state.x);  // else the last step's, as density()
  DrawnParticles out;
  for (size_t i = 0; i < state.x.size(); ++i) {
    const dvec3 xi = state.x[i];
    // The position's mean and the shape's covariance weigh the neighbours differently
    // (smoothed_positions.comp says why).
    dvec3 towards(0.0), first(0.0);
    glm::dmat3 second(0.0);
    double position_weights = 0, weights = 0;
    int count = 0;
    for_each_neighbour(i, xi, [&](size_t j, const Image& m) {
      dvec3 d = m.of(state.x[j]) - xi;
      const double w = kernels::smoothing_weight(d, d_.h);
      if (w <= 0) return;
      const double wp = kernels::position_weight(d, d_.h);
      d /= d_.h;
      towards += wp * d;
      position_weights += wp;
      first += w * d;
      second += w * glm::outerProduct(d, d);
      weights += w;
      ++count;
    });
    out.x.push_back(xi + POSITION_SMOOTHING * d_.h * towards / position_weights);
    const dvec3 mean = first / weights;
    const auto [shape, longest_axis] = drawn_shape(second / weights - glm::outerProduct(mean, mean), count);
    out.shape.push_back(shape);
    out.longest_axis.push_back(longest_axis);
  }
  return out;
}

glm::dvec3 ReferenceSolver::project_out_of_solids(glm::dvec3 x, double& work) const {
  for (const Obstacle& o : d_.obstacles) {
    const dvec3 out = project_out(o, x, d_.wall_min, d_.wall_max);
    if (out != x && !push_body(o.body, out, out - x)) work += push_work(out - x, o.displacement(out), d_.dt);
    x = out;
  }
  return glm::clamp(x, d_.wall_min, d_.wall_max);
}

ParticleFrame ReferenceSolver::read_frame() const {
  ParticleFrame f;
  for (size_t i = 0; i < state.x.size(); ++i) {
    f.x.emplace_back(glm::vec3(state.x[i]), 0.0f);
    f.v.emplace_back(glm::vec3(state.v[i]), 0.0f);
    f.rho.push_back(float(state.rho[i]));
    f.id.push_back(state.id[i]);
  }
  for (size_t i = 0; i < drawn.x.size(); ++i) {
    f.x_smooth.emplace_back(glm::vec3(drawn.x[i]), 0.0f);
    for (const glm::vec4& half : encode_shape(drawn.shape[i], drawn.longest_axis[i])) f.shape.push_back(half);
  }
  add_white_water(f, white);
  return f;
}

// One frame: the plan's passes (sim/frame_plan.hpp) in order, as the GPU records them.
FrameStats ReferenceSolver::advance(int steps) {
  const auto start = std::chrono::steady_clock::now();
  iterations_run_ = long(steps) * d_.solver.iterations;  // the adaptive pairs add theirs
  solid_work_ = 0;
  step_in_frame_ = 0;
  watch_ = {};
  frame_time_ = steps * d_.dt;
  drawn = {};
  // The flow's clock stands still with the solids' (the settle): no water enters or leaves.
  const FlowCount flow = steps > 0 && !solids_held_ ? apply_flow() : FlowCount{};
  if (!solids_held_) flow_steps_ += steps;
  double steps_ms = -1;  // the steps' wall time, to the frame's end
  for (const PlannedPass& pass : frame_plan(d_, steps, outputs_)) {
    if (steps_ms < 0 && !in_step(pass.group))
      steps_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    run(pass);
  }
  ++frames_advanced_;
  FrameStats s = measured_;
  s.step_ms = steps > 0 ? steps_ms / steps : 0.0;
  s.iterations = steps > 0 ? double(iterations_run_) / steps : 0.0;
  s.divergence = watch_;
  s.count_flow(flow, state.x.size());
  return s;
}

// The frame's drains and emitters on the state itself (sim/flow.hpp), at the time its steps start.
FlowCount ReferenceSolver::apply_flow() {
  const double t = double(flow_steps_) * d_.dt;
  if (!d_.flows() || !flow_due(d_.emitters, d_.drains, t, d_.spacing)) return {};
  std::vector<std::vector<dvec3>*> carried{&state.x_pred};
  if (state.curl.size() == state.x.size()) carried.push_back(&state.curl);
  std::vector<std::vector<double>*> scalars{&state.rho};
  if (state.lambda.size() == state.x.size()) scalars.push_back(&state.lambda);
  const FlowCount flow = pbflow::apply_flow(d_.emitters, d_.drains, d_.flow_frame(capacity_), t,
                                            {state.x, state.v, state.id, carried, scalars}, next_id_);
  neighbours_built_ = false;
  return flow;
}

}  // namespace pbflow
