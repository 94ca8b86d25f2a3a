#include "sim/params.hpp"

#include "common/input_error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "sim/kernels.hpp"
#include "sim/lattice.hpp"
#include "sim/stability.hpp"
#include "shaders/contract.h"

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

bool Derived::moving() const {
  return steerable || tank.moves() ||
         std::any_of(obstacles.begin(), obstacles.end(), [](const Obstacle& o) { return o.moves(); });
}

bool Derived::sticky() const {
  return std::any_of(obstacles.begin(), obstacles.end(), [](const Obstacle& o) { return !o.slip; });
}

void Derived::make_steerable() {
  steerable = true;
  for (Obstacle& o : obstacles) o.draggable = true;
}

void Derived::carry_solids(const std::vector<Obstacle>& placed, const TankMotion& motion, const std::vector<Body>& moving) {
  obstacles = placed;
  bodies = moving;
  if (steerable) make_steerable();  // carried from one that was not
  tank = motion;
  measure_open({});
}

void Derived::shake(const Motion& m, double now) {
  tank.change(m, now);
  if (tank.tilting(now)) tilt(tank.tilt_target(), now);
}

void Derived::tilt(const glm::dquat& to, double now) {
  const double turn = glm::angle(glm::inverse(tank.tilt_at(now)) * to), fastest = kSolidStep * spacing / dt;
  // The walls move at the tilt's speed and the tank's own motion's (a scene's, a shake) added: the
  // tilt takes what that leaves (a thousandth of it at least, however slow the turn then is).
  const Motion& own = tank.motion();
  const double left = fastest - (own.moves() ? own.top_speed(reach(domain_min, domain_max, own.centre)) : 0.0);
  const double corner_path = std::min(turn, 2 * std::numbers::pi - turn) * reach(domain_min, domain_max, tank.pivot());
  tank.tilt(to, now, std::max(1.0, 1.5 * corner_path / std::max(left, 1e-3 * fastest)));
}

void Derived::drag(size_t k, const glm::dvec3& shift) {
  if (!steerable || k >= obstacles.size()) return;
  obstacles[k].shift_to = shift;
  obstacles[k].held = obstacles[k].body >= 0;
}

void Derived::release(size_t k) {
  if (k < obstacles.size()) obstacles[k].held = false;
}

std::vector<Pose> Derived::obstacle_poses() const {
  std::vector<Pose> poses;
  for (const Obstacle& o : obstacles) poses.push_back(o.pose);
  return poses;
}

namespace {
// How far a viewer's hand may shift `o` in one step: what kSolidStep spacings leave beside its
// own motion's fastest point (none where that takes them all).
double hand_step(const Obstacle& o, double spacing, double dt) {
  const double own = o.motion.top_speed(glm::length(o.middle() - o.motion.centre) + o.extent()) * dt;
  return std::max(kSolidStep * spacing - own, 0.0);
}
}  // namespace

bool Derived::move_solids(double t) {
  std::vector<Reach> near;
  std::vector<bool> moved(obstacles.size(), false);
  for (size_t k = 0; k < obstacles.size(); ++k) {
    Obstacle& o = obstacles[k];
    if (!o.moves()) continue;
    if (o.body < 0) {  // a body's pose is its dynamics' (BodyWorld::predict, before this)
      const glm::dvec3 left = o.shift_to - o.shift;
      const double most = hand_step(o, spacing, dt);
      o.shift += glm::length(left) > most ? most * glm::normalize(left) : left;
      Pose p = o.motion.at(t);
      p.translation += o.shift;
      o.move_to(p);
    } else if (o.held) {  // after Bullet's step: the hand leads it from where it stood
      const glm::dvec3 left = o.middle() + o.shift_to - o.previous.world(o.middle());
      const double most = kSolidStep * spacing;
      o.pose = o.previous;
      o.pose.translation += glm::length(left) > most ? most * glm::normalize(left) : left;
    }
    if (o.pose == o.previous) continue;  // a draggable obstacle left where it is
    moved[k] = true;
    for (const Pose* p : {&o.previous, &o.pose}) near.push_back({p->world(o.middle()), o.extent()});
  }
  if (near.empty() || coarse.open.empty()) return false;
  measure_open(near, moved);
  return true;
}

double Derived::nearest_moving_solid(const glm::dvec3& x, glm::dvec3& normal, glm::dvec3& velocity) const {
  double nearest = std::numeric_limits<double>::infinity();
  normal = velocity = glm::dvec3(0.0);
  for (const Obstacle& o : obstacles) {
    glm::dvec3 n;
    if (!o.moves() || o.dynamic()) continue;  // a body's work on the fluid is in its energy
    if (const double d = o.grown(-keep_out).surface(x, n); d < nearest)
      nearest = d, normal = n, velocity = o.displacement(x) / dt;
  }
  return nearest;
}

void Derived::hold_solids() {
  tank_kick = tank.held(dt, gravity);
  for (Obstacle& o : obstacles) o.previous = o.pose;
}

void Derived::measure_open(const std::vector<Reach>& near, const std::vector<bool>& moved) {
  if (coarse.open.empty() || obstacles.empty()) return;  // no coarse correction; open everywhere
  std::vector<Obstacle> still, moving;  // the obstacles' own surfaces, where the mirrors lie
  for (size_t k = 0; k < obstacles.size(); ++k)
    (k < moved.size() && moved[k] ? moving : still).push_back(obstacles[k].grown(-keep_out));
  const size_t words = kReachWords;
  if (near.empty() || moved != coarse.moved || coarse.still_inside.empty()) {  // other solids still: anew
    coarse.moved = moved;
    coarse.still_inside.assign(size_t(coarse.count()) * words, 0);
    coarse.still_taken.assign(size_t(coarse.count()), false);
  }
  std::vector<uint64_t> inside(words);
  for (int k = 0; k < coarse.count(); ++k) {
    const glm::dvec3 node = wall_min + (glm::dvec3(coarse.node(k)) + 0.5) * coarse.cell;
    // A node gathers from a box one cell to each side: does it meet the reach's sphere?
    auto meets = [&](const Reach& r) {
      return glm::length(r.centre - glm::clamp(r.centre, node - coarse.cell, node + coarse.cell)) < r.radius;
    };
    if (!near.empty() && std::none_of(near.begin(), near.end(), meets)) continue;
    const std::span<uint64_t> kept(coarse.still_inside.data() + size_t(k) * words, words);
    if (!coarse.still_taken[size_t(k)])
      for (const Obstacle& o : still) mark_inside(o, node, coarse.cell, kept);
    coarse.still_taken[size_t(k)] = true;
    std::copy(kept.begin(), kept.end(), inside.begin());
    for (const Obstacle& o : moving) mark_inside(o, node, coarse.cell, inside);
    coarse.open[size_t(k)] = float(open_share(inside));
  }
  if (std::none_of(obstacles.begin(), obstacles.end(), [](const Obstacle& o) { return o.moves(); }))
    coarse.still_inside = {}, coarse.still_taken = {};  // nothing will move: kept for nothing
}

size_t Derived::capacity_for(size_t start) const {
  size_t first = start;  // the start and every emitter's first layer
  for (const Emitter& e : emitters) first += e.inlet.size();
  if (stated_capacity > 0 && size_t(stated_capacity) < first)
    throw InputError("capacity " + std::to_string(stated_capacity) + " holds less than the start's " +
                     std::to_string(start) + " particles and the emitters' first layers (" + std::to_string(first) + ")");
  if (stated_capacity > 0) return size_t(stated_capacity);
  double total = double(start);
  for (const Emitter& e : emitters) {
    const double seconds = std::max(std::min(e.stop, run_seconds) - e.start, 0.0);
    total += std::floor(seconds * e.speed / spacing + 1.0) * double(e.inlet.size());
  }
  return size_t(std::min(total, double(kMaxParticles)));
}

FlowFrame Derived::flow_frame(size_t capacity) const {
  return {mass, spacing, gravity, lowest(), capacity, emitting};
}

}  // namespace pbflow
