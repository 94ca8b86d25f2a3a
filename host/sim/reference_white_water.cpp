// The reference's white water (shaders/white_water.h): white_water_emit.comp and
// white_water_advect.comp in double, in the same order.
#include <algorithm>

#include "sim/kernels.hpp"
#include "sim/reference_solver.hpp"
#include "sim/white_water.hpp"

namespace pbflow {

using glm::dvec3;

void ReferenceSolver::set_outputs(FrameOutputs outputs) {
  outputs = outputs_made(d_, outputs);
  if (outputs.white_water != outputs_.white_water) white.clear();  // on starts with none alive
  outputs_ = outputs;
}

size_t ReferenceSolver::white_water_capacity() const {
  return d_.white_capacity();
}

void ReferenceSolver::upload_white_water(const std::vector<WhiteParticle>& w) {
  white.assign(w.begin(), w.begin() + std::min(w.size(), white_water_capacity()));
}

void ReferenceSolver::white_water_advect(double elapsed) {
  std::vector<WhiteParticle> alive;
  for (WhiteParticle p : white) {
    // The fluid around it: its density (the kind) and its velocity interpolated with the same kernel.
    double density = 0;
    dvec3 carried(0.0);
    for_each_candidate(p.x, [&](size_t j) {
      const dvec3 d = state.x[j] - p.x;
      const double w = kernels::poly6(glm::dot(d, d), d_.h);
      density += w;
      carried += w * state.v[j];
    });
    const uint32_t kind = white_water_kind(d_.mass * density / d_.rho0);
    if (density > 0) carried /= density;
    const dvec3 g = d_.tank_gravity();
    if (kind == WHITE_SPRAY)
      p.v += elapsed * g;
    else if (kind == WHITE_FOAM)
      p.v = carried;
    else
      p.v += -WHITE_BUOYANCY * elapsed * g + WHITE_DRAG * (carried - p.v);
    double unused = 0;  // white water does no work
    const dvec3 to = p.x + elapsed * p.v, moved = move_outside_solids(p.x, to, unused);
    for (int a = 0; a < 3; ++a)
      if (moved[a] != to[a]) p.v[a] = 0;  // stopped by a wall or an obstacle
    p.x = moved;
    p.life -= elapsed;
    p.tag = (p.tag & ~((1u << WHITE_KIND_BITS) - 1u)) | kind;
    if (p.life > 0 && alive.size() < white_water_capacity()) alive.push_back(p);
  }
  white = std::move(alive);
}

void ReferenceSolver::white_water_emit(double elapsed, uint32_t frame) {
  if (!neighbours_current_) build_neighbours(state.x);  // else the last step's, as density()
  const double unit = d_.flow_speed;  // white_water.h's speed unit
  for (size_t i = 0; i < state.x.size(); ++i) {
    const dvec3 xi = state.x[i], vi = state.v[i];
    if (glm::length(vi) / unit <= WHITE_SPEED_MIN) continue;  // too slow to make any (white_water_born's gate)
    double trapped = 0, weights = 0;
    dvec3 towards(0.0);
    for_each_neighbour(i, xi, [&](size_t j, const Image& m) {
      const dvec3 d = m.of(state.x[j]) - xi, vij = vi - m.velocity(state.v[j]);
      const double w = kernels::position_weight(d, d_.h), r = glm::length(d), s = glm::length(vij);
      weights += w;
      towards += w * d;
      if (r > 0 && s > 0) trapped += w * s * (1 + glm::dot(vij, d) / (s * r));
    });
    WhitePotentials p{trapped / weights / unit, glm::length(towards) / (weights * d_.h), 0, glm::length(vi) / unit};
    if (p.surface > 0) p.outward = glm::dot(vi, -glm::normalize(towards)) / unit;
    const uint32_t id = state.id[i];  // the emitter's id, as the GPU's (not its place: drains move them)
    const uint32_t born = white_water_born(p, d_.white_water.emission * elapsed, id, frame);
    for (uint32_t b = 0; b < born && white.size() < white_water_capacity(); ++b) {
      const WhiteRandom r(id, b, frame);
      white.push_back({xi + d_.spacing * (r.offset() - 0.5), vi, d_.white_water.lifetime * (0.5 + r.life()),
                       ((id & WHITE_TAG_ID_MASK) * WHITE_MOST_BORN + b) << WHITE_KIND_BITS | WHITE_FOAM});
    }
  }
}

}  // namespace pbflow
