#include "sim/flow.hpp"

#include <cmath>

namespace pbflow {

std::vector<glm::dvec3> inlet_points(const Emitter& e, double spacing) {
  // Two axes in the plane: across, the unit axis least along the normal made perpendicular.
  const glm::dvec3 n = e.normal;
  const glm::dvec3 pick = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 0, 1);
  const glm::dvec3 across = glm::normalize(pick - glm::dot(pick, n) * n), along = glm::cross(n, across);
  const glm::dvec2 half = e.radius > 0 ? glm::dvec2(e.radius) : 0.5 * e.size;
  const int ni = int(std::floor(half.x / spacing + 1e-9)), nj = int(std::floor(half.y / spacing + 1e-9));
  std::vector<glm::dvec3> points;
  for (int i = -ni; i <= ni; ++i)
    for (int j = -nj; j <= nj; ++j) {
      const glm::dvec2 p(i * spacing, j * spacing);
      if (e.radius > 0 && glm::length(p) > e.radius + 1e-9 * spacing) continue;
      points.push_back(e.centre + p.x * across + p.y * along);
    }
  return points;
}

namespace {

void drain(const std::vector<Drain>& drains, const FlowFrame& f, FlowParticles& p, FlowCount& count) {
  if (drains.empty()) return;
  size_t kept = 0;
  for (size_t i = 0; i < p.x.size(); ++i) {
    bool inside = false;
    for (const Drain& d : drains) inside = inside || d.contains(p.x[i]);
    if (inside) {
      count.energy -= f.energy(p.x[i], p.v[i]);
      ++count.drained;
      continue;
    }
    p.x[kept] = p.x[i], p.v[kept] = p.v[i], p.id[kept] = p.id[i];
    for (auto* a : p.carried) (*a)[kept] = (*a)[i];
    for (auto* a : p.carried_scalars) (*a)[kept] = (*a)[i];
    ++kept;
  }
  for (auto* a : {&p.x, &p.v}) a->resize(kept);
  p.id.resize(kept);
  for (auto* a : p.carried) a->resize(kept);
  for (auto* a : p.carried_scalars) a->resize(kept);
}

void append(const glm::dvec3& x, const glm::dvec3& v, FlowParticles& p, uint32_t& next_id) {
  p.x.push_back(x);
  p.v.push_back(v);
  p.id.push_back(next_id++);
  for (auto* a : p.carried) a->push_back(glm::dvec3(0.0));
  for (auto* a : p.carried_scalars) a->push_back(0.0);
}

}  // namespace

bool flow_due(const std::vector<Emitter>& emitters, const std::vector<Drain>& drains, double t, double spacing) {
  if (!drains.empty()) return true;
  for (const Emitter& e : emitters)
    if (e.layer_time(e.layers, spacing) <= t && e.layer_time(e.layers, spacing) < e.stop) return true;
  return false;
}

FlowCount apply_flow(std::vector<Emitter>& emitters, const std::vector<Drain>& drains, const FlowFrame& f,
                     double t, FlowParticles p, uint32_t& next_id) {
  FlowCount count;
  drain(drains, f, p, count);
  for (Emitter& e : emitters)
    for (double due = e.layer_time(e.layers, f.spacing); due <= t && due < e.stop; due = e.layer_time(++e.layers, f.spacing)) {
      if (!f.emitting) continue;
      if (p.x.size() + e.inlet.size() > f.capacity) {
        count.paused = true;  // the layer is skipped: the jet resumes when the drains make room
        continue;
      }
      const glm::dvec3 v = e.speed * e.normal, shift = (t - due) * v;
      for (const glm::dvec3& at : e.inlet) {
        append(at + shift, v, p, next_id);
        count.energy += f.energy(at + shift, v);
        ++count.emitted;
      }
    }
  return count;
}

}  // namespace pbflow
