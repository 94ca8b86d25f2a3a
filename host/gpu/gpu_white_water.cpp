// The GPU's white water (sim/white_water.hpp): its lists read and written, its passes. Its order
// comes from prefix sums, never from atomics, so a run's white water is the same on every run.
#include "gpu/gpu_solver.hpp"

#include <algorithm>

#include "vk/commands.hpp"
#include "vk/context.hpp"

namespace pbflow {

std::vector<WhiteParticle> GpuSolver::white_water() const {
  if (!outputs_.white_water) return {};
  const uint32_t count = std::min(white_count_.download<uint32_t>(1)[0], uint32_t(white_water_capacity()));
  const auto x = white_x_[0].download<glm::vec4>(count), v = white_v_[0].download<glm::vec4>(count);
  std::vector<WhiteParticle> out;
  for (uint32_t k = 0; k < count; ++k) out.push_back(WhiteParticle::unpacked(x[k], v[k]));
  return out;
}

void GpuSolver::upload_white_water(const std::vector<WhiteParticle>& w) {
  if (!outputs_.white_water) return;
  const uint32_t count = uint32_t(std::min(w.size(), white_water_capacity()));
  ParticleFrame packed;
  add_white_water(packed, {w.begin(), w.begin() + count});
  const uint32_t words[2] = {count, count};
  white_count_.upload(std::span<const uint32_t>(words, 2));
  if (count) {
    white_x_[0].upload(std::span<const glm::vec4>(packed.white_x));
    white_v_[0].upload(std::span<const glm::vec4>(packed.white_v));
  }
}

void GpuSolver::white_water_advect(double elapsed) {
  sim_.elapsed = float(elapsed);
  cmd_.fill(white_survivors_.data(), 0);
  bind_particle_pass(white_advect_);
  cmd_.bind("cell_start", grid_.cell_start());
  cmd_.bind("x", at(X));
  cmd_.bind("v", at(V));
  cmd_.bind("white_count_in", white_count_);
  cmd_.bind("white_x_in", white_x_[0]);
  cmd_.bind("white_v_in", white_v_[0]);
  cmd_.bind("keep", white_survivors_.data());
  cmd_.bind("white_x_out", white_x_[1]);
  cmd_.bind("white_v_out", white_v_[1]);
  cmd_.bind("obstacles", obstacles_);
  cmd_.dispatch(uint32_t(white_water_capacity()));
  white_survivors_.run(cmd_);
  bind_particle_pass(white_compact_);  // the survivors back into [0], in order, and their count
  cmd_.bind("slots", white_survivors_.data());
  cmd_.bind("white_x_in", white_x_[1]);
  cmd_.bind("white_v_in", white_v_[1]);
  cmd_.bind("white_count", white_count_);
  cmd_.bind("white_x_out", white_x_[0]);
  cmd_.bind("white_v_out", white_v_[0]);
  cmd_.dispatch(uint32_t(white_water_capacity()) + 1);
}

void GpuSolver::white_water_emit(double elapsed, uint32_t frame) {
  sim_.elapsed = float(elapsed);
  sim_.frame = frame;
  cmd_.fill(white_births_.data(), 0);
  run_neighbour_pass(white_emit_, nullptr, [&] {
    cmd_.bind("obstacles", obstacles_);  // the solids' mirrors (solids.glsl)
    cmd_.bind("x", at(X));
    cmd_.bind("v", at(V));
    cmd_.bind("id", id_[id_current_]);
    cmd_.bind("births", white_births_.data());
  });
  white_births_.run(cmd_);
  bind_particle_pass(white_birth_);
  cmd_.bind("x", at(X));
  cmd_.bind("v", at(V));
  cmd_.bind("id", id_[id_current_]);
  cmd_.bind("slots", white_births_.data());
  cmd_.bind("white_count", white_count_);
  cmd_.bind("white_x", white_x_[0]);
  cmd_.bind("white_v", white_v_[0]);
  cmd_.dispatch(n_);
  const VkBufferCopy total{sizeof(uint32_t), 0, sizeof(uint32_t)};  // the count after the births, over the base
  vkCmdCopyBuffer(cmd_.handle(), white_count_.handle(), white_count_.handle(), 1, &total);
  vk::memory_barrier(cmd_.handle());
}

}  // namespace pbflow
