#include "scene/derive.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <type_traits>
#include <variant>
#include <vector>

#include "scene/keys.hpp"
#include "shaders/contract.h"
#include "sim/lattice.hpp"
#include "sim/stability.hpp"

namespace pbflow {

namespace {

// Every key a shader reads: those that set a SolverParams or WhiteWaterParams member.
std::vector<ParamKey> shader_keys() {
  std::vector<ParamKey> keys;
  for (const SceneKey& k : scene_keys())
    if (const ParamTarget* target = std::get_if<ParamTarget>(&k.target)) keys.push_back({k.name, *target});
  return keys;
}

// LDC's K, its stability limit and the room under its cap; the dashpot's limit.
void derive_forces(const Scene& scene, Derived& d) {
  d.ldc_k_limit = 4.0 / (d.dt * d.dt * ldc_stiffness_max(scene.solver.kernel_ratio));
  d.ldc_k = scene.solver.method != Method::Ldc ? 0.0
            : scene.solver.ldc_k >= 0          ? scene.solver.ldc_k
                                               : scene.solver.ldc_strength * d.ldc_k_limit;
  if (d.ldc_k >= d.ldc_k_limit) {
    std::ostringstream m;
    m << "solver.ldc_k = " << d.ldc_k << " 1/s^2 is past the LDC force's stability limit at dt = " << d.dt
      << " s (" << d.ldc_k_limit << "); leave it out and set solver.ldc_strength (a fraction of that limit) instead";
    throw InputError(m.str());
  }
  d.ldc_room = d.ldc_k > 0 ? kLdcCap * d.ldc_k_limit / d.ldc_k : 1.0;
  d.damping_limit = 1.5 / damping_gain_max(scene.solver.kernel_ratio);
}

// The domain, its walls and obstacles as the particles' centres meet them, and the grid.
void derive_domain(const Scene& scene, Derived& d) {
  const double s = scene.particle_spacing;
  d.gravity = scene.gravity;
  d.domain_min = scene.domain.min;
  d.domain_max = scene.domain.max;
  // Particles are spheres of diameter `spacing`: their centres stay half a spacing off the walls.
  d.keep_out = 0.5 * s;
  d.wall_min = d.domain_min + d.keep_out;
  d.wall_max = d.domain_max - d.keep_out;
  for (const Obstacle& o : scene.obstacles) d.obstacles.push_back(o.grown(d.keep_out)), d.walls_mirror &= !o.container;
  d.bodies = scene.bodies;
  d.tank = TankMotion(scene.tank_motion, scene.domain.floor_centre());
  glm::dvec3 size = d.domain_max - d.domain_min;
  if (glm::any(glm::lessThan(size, glm::dvec3(s))))
    throw InputError("the domain must be at least one particle_spacing wide on every axis");
  glm::dvec3 cells = glm::ceil(size / d.h);
  if (cells.x * cells.y * cells.z > 1 << 26)
    throw InputError("the domain holds too many grid cells (over 2^26) at this particle_spacing");
  d.grid = glm::ivec3(cells);
}

// The coarse correction's grid: pairs always; a single iteration only where it runs smoothed
// (constraint_schedule): beside an unsmoothed one the correction made energy.
void derive_coarse(double spacing, Derived& d) {
  if (d.solver.iterations < 2 && !d.smooths_lambda()) return;
  const glm::dvec3 span = d.wall_max - d.wall_min;
  d.coarse.nodes = glm::max(glm::ivec3(1), glm::ivec3(glm::round(span / (COARSE_CELL * spacing))));
  for (int a = 0; a < 3; ++a) d.coarse.cell[a] = span[a] > 0 ? span[a] / d.coarse.nodes[a] : COARSE_CELL * spacing;
  d.coarse.strength = d.solver.iterations == 1 ? COARSE_LONE_STRENGTH : COARSE_STRENGTH;
  d.coarse.open.assign(size_t(d.coarse.count()), 1.0f);
  d.measure_open({});
}

}  // namespace

Derived derive(const Scene& scene) {
  Derived d;
  d.solver = scene.solver;
  d.white_water = scene.white_water;
  d.shader_keys = shader_keys();
  const double s = scene.particle_spacing;
  d.h = scene.solver.kernel_ratio * s;
  d.spacing = s;
  d.dt = 1.0 / (scene.fps * scene.solver.substeps);
  // Ten times the speed of a fall through the whole domain (at least 1 m/s): no flow of the
  // scene reaches it, a blow-up passes it within a few steps.
  double emitted = 0;
  for (const Emitter& e : scene.emitters) emitted = std::max(emitted, e.speed);
  d.speed_limit = 10.0 * std::max({fall_speed(scene), solid_speed(scene), emitted, 1.0});
  d.flow_speed = std::max({fall_speed(scene), solid_speed(scene), emitted, 0.1});
  d.rho0 = scene.solver.rest_density;
  d.mass = lattice_mass(s, d.h, d.rho0);
  d.epsilon = scene.solver.relaxation * lattice_gradient_sq(s, d.h, d.mass, d.rho0);
  d.travel = fall_speed(scene) * d.dt / d.h;
  if (d.solver.lambda_smoothing == SolverParams::kChosenSmoothing)
    d.solver.lambda_smoothing = default_smoothing(d.solver.iterations, d.travel);
  d.jacobi_gain_max = jacobi_gain_max(scene.solver.kernel_ratio, scene.solver.relaxation);
  d.paired_gain_max =
      d.solver.lambda_smoothing == 0
          ? d.jacobi_gain_max
          : jacobi_gain_max(scene.solver.kernel_ratio, scene.solver.relaxation, 0.0, d.solver.lambda_smoothing);
  derive_forces(scene, d);
  // 4/3 pi (h / spacing)^3 neighbours inside h at rho0 (33.5 at 2), rounded up to 8.
  const double at_rest = 4.0 / 3.0 * std::numbers::pi * std::pow(scene.solver.kernel_ratio, 3);
  d.neighbour_capacity = 8 * uint32_t(std::ceil(kNeighbourHeadroom * at_rest / 8));
  derive_domain(scene, d);
  derive_coarse(s, d);
  d.emitters = scene.emitters;
  d.drains = scene.drains;
  d.stated_capacity = scene.capacity;
  d.run_seconds = scene.frames / scene.fps;
  if (d.white_water.max_particles == WhiteWaterParams::kChosenCapacity)  // as many as the fluid's
    d.white_water.max_particles = int(std::clamp(std::ceil(particle_estimate(scene)), 1.0, double(kMaxParticles)));
  return d;
}

namespace {
// The substeps that keep a fall within one kernel radius a step (at most 1000, the key's most).
int substeps_within_h(const Scene& scene, const Derived& d) {
  return int(std::min(std::ceil(scene.solver.substeps * d.travel), 1000.0));
}
}  // namespace

std::string time_step_warning(const Scene& scene, const Derived& d) {
  if (d.travel <= 1.0) return "";
  std::ostringstream m;
  m.precision(3);
  m << "warning: dt = " << d.dt << " s lets a particle falling through the domain (" << fall_speed(scene)
    << " m/s) move " << d.travel << " kernel radii per step, past its neighbours; ";
  if (scene.solver.substeps * d.travel <= 1000)
    m << "solver.substeps=" << substeps_within_h(scene, d)
      << " keeps it within one (tunnelling and blow-ups are likely otherwise)";
  else
    m << "even 1000 solver.substeps (the most) do not keep it within one: raise fps or particle_spacing";
  return m.str();
}

std::string divergence_advice(const Scene& scene, const Derived& d) {
  const SolverParams& p = scene.solver;
  std::vector<std::string> tries;
  auto say = [&](auto&&... parts) {
    std::ostringstream m;
    m.precision(3);
    (m << ... << parts);
    tries.push_back(m.str());
  };
  if (d.travel > 1.0)
    say("solver.substeps=", substeps_within_h(scene, d), " (a fall moves ", d.travel, " kernel radii a step at ",
        p.substeps, ")");
  if (p.vorticity > 0) say("a smaller solver.vorticity (", p.vorticity, " m/s adds energy)");
  if (p.method == Method::Ldc && p.ldc_k >= 0)
    say("a smaller solver.ldc_k (", p.ldc_k, " 1/s², ", p.ldc_k / d.ldc_k_limit, " of the step's limit)");
  else if (p.method == Method::Ldc && p.ldc_strength > scene_defaults().solver.ldc_strength)
    say("a smaller solver.ldc_strength (", p.ldc_strength, ")");
  if (tries.empty()) say("more solver.substeps or solver.iterations");
  std::string advice = "try " + tries.front();
  for (size_t k = 1; k < tries.size(); ++k) advice += ", " + tries[k];
  return advice;
}

}  // namespace pbflow
