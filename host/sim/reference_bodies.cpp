// The reference's side of the rigid bodies (sim/solids/coupling.hpp): the pushes its passes give
// them, and each body's water line for its buoyancy.
#include <limits>

#include "sim/reference_solver.hpp"

namespace pbflow {

using glm::dvec3;

bool ReferenceSolver::push_body(int b, const dvec3& x, const dvec3& dx) const {
  if (b < 0 || !d_.obstacles[d_.bodies[size_t(b)].obstacle].dynamic()) return false;  // a held body's is the hand's work
  const Body& body = d_.bodies[size_t(b)];
  if (!solids_held_) bodies_.pushes()[size_t(b)].add(body.world_centre(d_.obstacles[body.obstacle].pose), x, dx, d_.mass);
  return true;
}

void ReferenceSolver::answer_bodies(bool kick) {
  if (d_.bodies.empty() || solids_held_) return;
  if (kick)
    bodies_.kick(d_);
  else
    bodies_.give_way(d_);
}

void ReferenceSolver::add_buoyancy(const std::vector<dvec3>& grad) {
  if (solids_held_) return;
  const dvec3 lift = up(d_);
  std::vector<double> lines;
  for (const Body& b : d_.bodies) {
    const Obstacle& o = d_.obstacles[b.obstacle];
    const double top = body_top(b, o, lift);
    double line = -std::numeric_limits<double>::infinity();
    for (const dvec3& x : state.x_pred) {  // beside it: not water lying on it
      dvec3 normal;
      if (const double height = glm::dot(x, lift); height <= top && o.surface(x, normal) < d_.spacing)
        line = std::max(line, height);
    }
    lines.push_back(line);
  }
  bodies_.add_buoyancy(d_, grad, lines);
}

}  // namespace pbflow
