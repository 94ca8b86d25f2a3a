#include "sim/solids/coupling.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/gtc/quaternion.hpp>

namespace pbflow {

namespace {
// How far a body's centre moved from its pose at the step's start.
glm::dvec3 centre_move(const Body& b, const Obstacle& o) { return b.world_centre(o.pose) - b.world_centre(o.previous); }

// A body's spin after the tank's step, in the tank's frame, such that Bullet's step (the turn
// exp(w dt) on the left) turns it as the world's step does, as the kick does for the fluid's
// positions: with R-, R, R+ the tank's rotations at the last two step ends and this one, the
// world's step exp(w_world dt), w_world the spin it had over the last step, is
// (R+^T R) exp(w dt) (R-^T R) in the frame.
glm::dvec3 spin_in_tank(const glm::dvec3& w, const TankKick& kick, double dt) {
  const double rate = glm::length(w);
  const glm::dquat own = rate > 0 ? glm::angleAxis(rate * dt, w / rate) : glm::dquat(1, 0, 0, 0);
  glm::dquat turn = glm::quat_cast(kick.turn_now) * own * glm::quat_cast(glm::transpose(kick.turn_before()) * kick.turn_now);
  if (turn.w < 0) turn = -turn;  // the shorter way round
  const glm::dvec3 axis(turn.x, turn.y, turn.z);
  const double half = std::atan2(glm::length(axis), turn.w);
  return half > 0 ? 2.0 * half / dt * glm::normalize(axis) : glm::dvec3(0.0);
}

}  // namespace

void BodyCoupling::predict(Derived& d) {
  if (d.bodies.empty()) return;
  // The solids grown by the keep-out margin meet at the particles' walls: a layer of fluid fits
  // between any two, so that none is squeezed out sideways at a speed no step carries.
  if (!world_) world_ = std::make_shared<BodyWorld>(d.bodies, d.obstacles, d.wall_min, d.wall_max, d.gravity);
  held_energy_.assign(d.bodies.size(), 0.0);
  tank_kicks_.assign(d.bodies.size(), {});
  for (size_t k = 0; k < d.bodies.size(); ++k) {
    Body& b = d.bodies[k];
    const Obstacle& o = d.obstacles[b.obstacle];
    if (o.held) held_energy_[k] = b.energy(o.pose, d.gravity, d.lowest());
    if (!o.dynamic() || d.tank_kick.none()) continue;
    tank_kicks_[k].velocity = d.tank_kick.at(b.world_centre(o.pose), b.velocity);  // the centre's, as a particle's
    b.velocity += tank_kicks_[k].velocity;
    const glm::dvec3 spin = spin_in_tank(b.angular_velocity, d.tank_kick, d.dt);
    tank_kicks_[k].spin = spin - b.angular_velocity;
    b.angular_velocity = spin;
  }
  world_->predict(d.bodies, d.obstacles, d.dt);
  moved_.clear();
  for (const Body& b : d.bodies) moved_.push_back(centre_move(b, d.obstacles[b.obstacle]));
}

void BodyCoupling::give_way(Derived& d) {
  for (size_t k = 0; k < d.bodies.size(); ++k) {
    const Body& b = d.bodies[k];
    Obstacle& o = d.obstacles[b.obstacle];
    if (o.dynamic()) {
      const glm::dvec3 before = b.world_centre(o.pose);
      o.pose = pbflow::give_way(b, o.pose, pushes_[k]);
      if (k < moved_.size()) moved_[k] += b.world_centre(o.pose) - before;
    }
    pushes_[k] = {};
  }
  if (!world_) return;
  for (const BodyWorld::Parting& p : world_->separate(d.bodies, d.obstacles)) part(d, p);
}

// Parting an overlap is inelastic: it takes away the two solids' approach over the step along its
// normal (up to its depth), shared by their inverse masses (BodyWorld::Parting's shares) so that
// their momentum is kept, and the rest of it only moves them, as Bullet's split impulse does.
// Made a velocity whole, it threw a ball driven into a light box and the box off the floor at 3.6 m/s.
void BodyCoupling::part(const Derived& d, const BodyWorld::Parting& p) {
  auto dynamic = [&](int k) { return k >= 0 && size_t(k) < moved_.size() && d.obstacles[d.bodies[size_t(k)].obstacle].dynamic(); };
  auto move = [&](int k) {  // a held body's is the hand's; a standing solid's none
    if (dynamic(k)) return moved_[size_t(k)];
    return k >= 0 ? centre_move(d.bodies[size_t(k)], d.obstacles[d.bodies[size_t(k)].obstacle]) : glm::dvec3(0.0);
  };
  const double depth = glm::length(p.overlap);
  if (depth <= 0) return;
  const glm::dvec3 normal = p.overlap / depth;
  const double cancel = std::min(depth, std::max(-glm::dot(move(p.a) - move(p.b), normal), 0.0));
  if (dynamic(p.a)) moved_[size_t(p.a)] += cancel * p.share_a * normal;
  if (dynamic(p.b)) moved_[size_t(p.b)] -= cancel * p.share_b * normal;
}

void BodyCoupling::kick(Derived& d) {
  for (size_t k = 0; k < d.bodies.size(); ++k) {
    if (const Obstacle& o = d.obstacles[d.bodies[k].obstacle]; o.dynamic()) d.bodies[k].kick(o.pose, pushes_[k]);
    pushes_[k] = {};
  }
}

void BodyCoupling::finish(Derived& d) {
  if (d.bodies.empty()) return;
  finish_bodies(d.bodies, d.obstacles, d.dt);
  for (size_t k = 0; k < d.bodies.size() && k < moved_.size(); ++k)
    if (d.obstacles[d.bodies[k].obstacle].dynamic()) d.bodies[k].velocity = moved_[k] / d.dt;
  // The tank's kick worked over the body's move in the step, as the fluid's does (a momentum
  // kick times the centre's velocity, a spin kick's moment times the spin).
  for (size_t k = 0; k < d.bodies.size() && k < tank_kicks_.size(); ++k) {
    const Body& b = d.bodies[k];
    work_ += b.mass * glm::dot(tank_kicks_[k].velocity, b.velocity) +
             glm::dot(b.spin_momentum(d.obstacles[b.obstacle].pose, tank_kicks_[k].spin), b.angular_velocity);
  }
  for (size_t k = 0; k < d.bodies.size() && k < held_energy_.size(); ++k)
    if (const Obstacle& o = d.obstacles[d.bodies[k].obstacle]; o.held)
      work_ += d.bodies[k].energy(o.pose, d.gravity, d.lowest()) - held_energy_[k];
}

void BodyCoupling::add_buoyancy(const Derived& d, const std::vector<glm::dvec3>& grad, const std::vector<double>& lines) {
  const glm::dvec3 lift = up(d);
  for (size_t k = 0; k < d.bodies.size(); ++k) {
    const Body& b = d.bodies[k];
    const Pose& pose = d.obstacles[b.obstacle].pose;
    const glm::dvec3 centre = b.world_centre(pose);
    for (const glm::dvec3& sample : b.samples) {
      const glm::dvec3 x = pose.world(sample);
      if (glm::dot(x, lift) > lines[k] + d.keep_out) continue;
      glm::dvec3 g(0.0);
      for_each_coarse_node(d, x, [&](int node, double w) { g += w * grad[size_t(node)]; });
      pushes_[k].add(centre, x, -d.coarse.strength * g, d.rho0 * b.sample_volume);
    }
  }
}

double BodyCoupling::energy(const Derived& d) {
  double e = 0;
  for (const Body& b : d.bodies) e += b.energy(d.obstacles[b.obstacle].pose, d.gravity, d.lowest());
  return e;
}

bool step_solids(Derived& d, BodyCoupling& bodies, double t) {
  d.step_tank(t);
  bodies.predict(d);
  return d.move_solids(t);
}

glm::dvec3 up(const Derived& d) {
  const glm::dvec3 g = glm::transpose(d.tank.pose().rotation) * d.gravity;
  return glm::length(g) > 0 ? -glm::normalize(g) : glm::dvec3(0, 1, 0);
}

double body_top(const Body& b, const Obstacle& o, const glm::dvec3& up) {
  double top = -std::numeric_limits<double>::infinity();
  for (const glm::dvec3& sample : b.samples) top = std::max(top, glm::dot(o.pose.world(sample), up));
  return top;
}

}  // namespace pbflow
