// The GPU's white water (sim/white_water.hpp): its lists read and written, its two passes.
#include "gpu/gpu_solver.hpp"

#include <algorithm>

namespace pbflow {

std::vector<WhiteParticle> GpuSolver::white_water() const {
  if (!outputs_.white_water) return {};
  const uint32_t count = std::min(white_count_[white_current_].download<uint32_t>(1)[0], white_capacity_);
  const auto x = white_x_[white_current_].download<glm::vec4>(count), v = white_v_[white_current_].download<glm::vec4>(count);
  std::vector<WhiteParticle> out;
  for (uint32_t k = 0; k < count; ++k)
    out.push_back(WhiteParticle::unpacked(x[k], v[k]));
  return out;
}

void GpuSolver::upload_white_water(const std::vector<WhiteParticle>& w) {
  if (!outputs_.white_water) return;
  const uint32_t count = uint32_t(std::min<size_t>(w.size(), white_capacity_));
  ParticleFrame packed;
  add_white_water(packed, {w.begin(), w.begin() + count});
  white_current_ = 0;
  white_count_[0].upload(std::span<const uint32_t>(&count, 1));
  if (count) {
    white_x_[0].upload(std::span<const glm::vec4>(packed.white_x));
    white_v_[0].upload(std::span<const glm::vec4>(packed.white_v));
  }
}

void GpuSolver::white_water_advect(double elapsed) {
  sim_.elapsed = float(elapsed);
  const int next = 1 - white_current_;
  cmd_.fill(white_count_[next], 0);
  bind_particle_pass(white_advect_);
  cmd_.bind("cell_start", grid_.cell_start());
  cmd_.bind("x", at(X));
  cmd_.bind("v", at(V));
  cmd_.bind("white_count_in", white_count_[white_current_]);
  cmd_.bind("white_x_in", white_x_[white_current_]);
  cmd_.bind("white_v_in", white_v_[white_current_]);
  cmd_.bind("white_count_out", white_count_[next]);
  cmd_.bind("white_x_out", white_x_[next]);
  cmd_.bind("white_v_out", white_v_[next]);
  cmd_.bind("obstacles", obstacles_);
  cmd_.dispatch(white_capacity_);
  white_current_ = next;
}

void GpuSolver::white_water_emit(double elapsed, uint32_t frame) {
  sim_.elapsed = float(elapsed);
  sim_.frame = frame;
  run_neighbour_pass(white_emit_, nullptr, [&] {
    cmd_.bind("x", at(X));
    cmd_.bind("v", at(V));
    cmd_.bind("id", id_[id_current_]);
    cmd_.bind("white_count", white_count_[white_current_]);
    cmd_.bind("white_x", white_x_[white_current_]);
    cmd_.bind("white_v", white_v_[white_current_]);
  });
}

}  // namespace pbflow
