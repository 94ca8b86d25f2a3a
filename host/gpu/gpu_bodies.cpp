// The GPU's rigid bodies (sim/solids/coupling.hpp): its passes sum each body's pushes on the
// device (solids.glsl's push_body, in fixed point: the same sums in any order); after each pass
// that pushed them the frame's commands are submitted, the sums read back, and the host answers
// as the reference does, its poses written into the next commands. A submit per pushing pass
// (five a step at pbf@2) only where the scene has bodies.
#include <cstring>
#include <limits>

#include "gpu/gpu_solver.hpp"
#include "vk/commands.hpp"
#include "vk/context.hpp"

namespace pbflow {

void GpuSolver::build_bodies() {
  body_line_ = particle_program("body_water_line");
  body_push_ = vk::Buffer(ctx_, plan_.body_push);
  body_read_ = vk::Buffer(ctx_, plan_.body_push, vk::Memory::Host);
  if (plan_.coarse_grad) body_grad_read_ = vk::Buffer(ctx_, plan_.coarse_grad, vk::Memory::Host);  // for the buoyancy
  body_push_.upload(std::span<const uint32_t>(std::vector<uint32_t>(plan_.body_push / sizeof(uint32_t), 0u)));
  bodies_ = BodyCoupling(d_.bodies.size());
}

// Each body's top along up and up itself into its words, then the highest particle beside it at
// most that high.
void GpuSolver::body_water_line() {
  static_assert(BODY_UP_WORD == BODY_TOP_WORD + 1);
  const glm::dvec3 lift = up(d_);
  for (size_t k = 0; k < d_.bodies.size(); ++k) {
    const float words[4] = {float(body_top(d_.bodies[k], d_.obstacles[d_.bodies[k].obstacle], lift)), float(lift.x),
                            float(lift.y), float(lift.z)};
    const uint32_t at = uint32_t((k * BODY_PUSH_WORDS + BODY_TOP_WORD) * sizeof(uint32_t));
    cmd_.update(body_push_, words, sizeof words, at);
  }
  bind_particle_pass(body_line_);
  cmd_.bind("x_pred", at(XPred));
  cmd_.bind("obstacles", obstacles_);
  cmd_.bind("body_pushes", body_push_);
  cmd_.dispatch(n_);
}

// After `pass`: where it pushed bodies, the commands so far run, and the bodies' answer.
void GpuSolver::answer_bodies(Pass pass) {
  if (d_.bodies.empty() || solids_held_) return;
  auto copy = [&](const vk::Buffer& from, const vk::Buffer& to) {
    const VkBufferCopy all{0, 0, from.bytes()};
    vkCmdCopyBuffer(cmd_.handle(), from.handle(), to.handle(), 1, &all);
  };
  copy(body_push_, body_read_);
  if (pass == Pass::Coarse) copy(coarse_grad_, body_grad_read_);
  vk::memory_barrier(cmd_.handle());
  finish();
  read_body_pushes();
  if (pass == Pass::Coarse) {
    const auto* g = static_cast<const glm::vec4*>(body_grad_read_.mapped());
    std::vector<glm::dvec3> grad;
    for (int k = 0; k < d_.coarse.count(); ++k) grad.emplace_back(glm::vec3(g[k]));
    bodies_.add_buoyancy(d_, grad, body_water_lines());
  }
  begin();
  cmd_.fill(body_push_, 0);
  if (pass == Pass::Viscosity) {
    bodies_.kick(d_);  // velocities only: the poses stand
  } else {
    bodies_.give_way(d_);
    update_obstacle_header();
  }
}

// The device's sums into BodyCoupling's pushes: momentum times the step (a particle's mass per
// metre of -dx) and its moment, recorded about the body frame's origin, taken to its centre.
void GpuSolver::read_body_pushes() {
  const auto* words = static_cast<const uint32_t*>(body_read_.mapped());
  auto sum = [&](size_t word) {
    int64_t value;
    const uint32_t pair[2] = {words[word], words[word + 1]};
    std::memcpy(&value, pair, sizeof value);  // low word first, two's complement
    return double(value) / BODY_FIXED_UNIT;
  };
  for (size_t k = 0; k < d_.bodies.size(); ++k) {
    const size_t first = k * BODY_PUSH_WORDS;
    const glm::dvec3 impulse = d_.mass * glm::dvec3(sum(first), sum(first + 2), sum(first + 4));
    const glm::dvec3 moment = d_.mass * glm::dvec3(sum(first + 6), sum(first + 8), sum(first + 10));
    const Pose& pose = d_.obstacles[d_.bodies[k].obstacle].pose;
    BodyPush& push = bodies_.pushes()[k];
    push.impulse += impulse;
    push.moment += moment - glm::cross(d_.bodies[k].world_centre(pose) - pose.world(glm::dvec3(0.0)), impulse);
  }
}

// The water lines body_water_line.comp left (ordered floats; 0: no particle beside the body).
std::vector<double> GpuSolver::body_water_lines() const {
  const auto* words = static_cast<const uint32_t*>(body_read_.mapped());
  std::vector<double> lines;
  for (size_t k = 0; k < d_.bodies.size(); ++k) {
    const uint32_t u = words[k * BODY_PUSH_WORDS + BODY_LINE_WORD];
    const uint32_t bits = (u & 0x80000000u) ? u & 0x7fffffffu : ~u;
    float line;
    std::memcpy(&line, &bits, sizeof line);
    lines.push_back(u == 0 ? -std::numeric_limits<double>::infinity() : double(line));
  }
  return lines;
}

}  // namespace pbflow
