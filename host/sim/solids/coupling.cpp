#include "sim/solids/coupling.hpp"

#include <limits>

namespace pbflow {

void BodyCoupling::predict(Derived& d) {
  if (d.bodies.empty()) return;
  // The solids grown by the keep-out margin meet at the particles' walls: a layer of fluid fits
  // between any two, so that none is squeezed out sideways at a speed no step carries.
  if (!world_) world_ = std::make_shared<BodyWorld>(d.bodies, d.obstacles, d.wall_min, d.wall_max, d.gravity);
  held_energy_.assign(d.bodies.size(), 0.0);
  for (size_t k = 0; k < d.bodies.size(); ++k)
    if (const Obstacle& o = d.obstacles[d.bodies[k].obstacle]; o.held) held_energy_[k] = d.bodies[k].energy(o.pose, d.gravity, d.lowest());
  world_->predict(d.bodies, d.obstacles, d.dt);
}

void BodyCoupling::give_way(Derived& d) {
  for (size_t k = 0; k < d.bodies.size(); ++k) {
    Obstacle& o = d.obstacles[d.bodies[k].obstacle];
    if (o.dynamic()) o.pose = pbflow::give_way(d.bodies[k], o.pose, pushes_[k]);
    pushes_[k] = {};
  }
  if (world_) world_->separate(d.bodies, d.obstacles);
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
  for (size_t k = 0; k < d.bodies.size() && k < held_energy_.size(); ++k)
    if (const Obstacle& o = d.obstacles[d.bodies[k].obstacle]; o.held)
      hand_work_ += d.bodies[k].energy(o.pose, d.gravity, d.lowest()) - held_energy_[k];
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

glm::dvec3 up(const Derived& d) { return glm::length(d.gravity) > 0 ? -glm::normalize(d.gravity) : glm::dvec3(0, 1, 0); }

double body_top(const Body& b, const Obstacle& o, const glm::dvec3& up) {
  double top = -std::numeric_limits<double>::infinity();
  for (const glm::dvec3& sample : b.samples) top = std::max(top, glm::dot(o.pose.world(sample), up));
  return top;
}

}  // namespace pbflow
