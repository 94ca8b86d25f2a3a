// The reference's rigid bodies (sim/solids/bodies.hpp): what each pass's pushes give them, their
// buoyancy from the coarse correction, and their step.
#include <limits>

#include "sim/reference_solver.hpp"

namespace pbflow {

using glm::dvec3;

bool ReferenceSolver::push_body(int b, const dvec3& x, const dvec3& dx) const {
  if (b < 0) return false;
  const Body& body = d_.bodies[size_t(b)];
  if (!solids_held_) pushes_[size_t(b)].add(body.world_centre(d_.obstacles[body.obstacle].pose), x, dx, d_.mass);
  return true;
}

void ReferenceSolver::predict_bodies() {
  if (d_.bodies.empty()) return;
  // The solids grown by the keep-out margin meet at the particles' walls: a layer of fluid fits
  // between any two, so that none is squeezed out sideways at a speed no step carries.
  if (!body_world_) body_world_ = std::make_shared<BodyWorld>(d_.bodies, d_.obstacles, d_.wall_min, d_.wall_max, d_.gravity);
  body_world_->predict(d_.bodies, d_.obstacles, d_.dt);
}

void ReferenceSolver::give_way_bodies() {
  if (solids_held_) return;
  for (size_t k = 0; k < d_.bodies.size(); ++k) {
    Obstacle& o = d_.obstacles[d_.bodies[k].obstacle];
    o.pose = give_way(d_.bodies[k], o.pose, pushes_[k]);
    pushes_[k] = {};
  }
  if (body_world_) body_world_->separate(d_.bodies, d_.obstacles);
}

void ReferenceSolver::finish_bodies_step() {
  if (d_.bodies.empty() || solids_held_) return;
  finish_bodies(d_.bodies, d_.obstacles, d_.dt);
}

void ReferenceSolver::kick_bodies() {
  if (solids_held_) return;
  for (size_t k = 0; k < d_.bodies.size(); ++k) {
    d_.bodies[k].kick(d_.obstacles[d_.bodies[k].obstacle].pose, pushes_[k]);
    pushes_[k] = {};
  }
}

// The coarse correction counts a solid as fluid at rest: the push it would give the fluid in a
// body's place (rho0 strength grad phi per volume) is the body's, over its volume below the
// water line beside it (the highest particle within a spacing of it and no higher than its top,
// water lying on it aside, and that particle's own half spacing): phi is zero only a cell above
// the surface, and the body's dry part counts as fluid there.
void ReferenceSolver::add_buoyancy(const std::vector<dvec3>& grad) {
  if (solids_held_) return;
  const dvec3 up = glm::length(d_.gravity) > 0 ? -glm::normalize(d_.gravity) : dvec3(0, 1, 0);
  for (size_t k = 0; k < d_.bodies.size(); ++k) {
    const Body& b = d_.bodies[k];
    const Obstacle& o = d_.obstacles[b.obstacle];
    double top = -std::numeric_limits<double>::infinity(), line = top;
    for (const dvec3& sample : b.samples) top = std::max(top, glm::dot(o.pose.world(sample), up));
    for (const dvec3& x : state.x_pred) {  // beside it: not water lying on it
      dvec3 normal;
      if (const double height = glm::dot(x, up); height <= top && o.surface(x, normal) < d_.spacing)
        line = std::max(line, height);
    }
    const dvec3 centre = b.world_centre(o.pose);
    for (const dvec3& sample : b.samples) {
      const dvec3 x = o.pose.world(sample);
      if (glm::dot(x, up) > line + d_.keep_out) continue;
      dvec3 g(0.0);
      for_each_coarse_node(x, [&](int node, double w) { g += w * grad[size_t(node)]; });
      pushes_[k].add(centre, x, -d_.coarse.strength * g, d_.rho0 * b.sample_volume);
    }
  }
}

}  // namespace pbflow
