#include "gpu/gpu_solver.hpp"

#include <bit>
#include <cstddef>
#include <chrono>
#include <numeric>
#include <stdexcept>

#include "gpu/memory_estimate.hpp"
#include "shaders/contract.h"
#include "vk/check.hpp"
#include "vk/context.hpp"

namespace pbflow {

namespace {

// The frame's read-back, one host-visible buffer: reduce_final.comp's two vec4 (mean
// compression, max compression, kinetic energy, max speed; potential energy), the adaptive
// iteration count copied from check_converged's indirect buffer, and watch.comp's words.
struct FrameResult {
  glm::vec4 measures, energy;
  uint32_t iterations, unused[3];
  uint32_t watch_flags, watch_first_step, watch_counts[3];
};
constexpr uint32_t kReduceThreads = 256;  // reduce_stats.comp and reduce_final.comp
struct ReduceFinalPush {
  uint32_t partial_count, particle_count;
  float mass;
};

struct CheckPush {  // check_converged.comp
  float target;
  uint32_t full_x, full_y, per_check;
};
uint32_t partial_count(uint32_t n) { return (n + kReduceThreads - 1) / kReduceThreads; }

// The formats the neighbour passes gather through (storage texel buffers, vk/program.hpp).
constexpr VkFormat kVec4 = VK_FORMAT_R32G32B32A32_SFLOAT, kFloat = VK_FORMAT_R32_SFLOAT, kUint = VK_FORMAT_R32_UINT,
                   kUvec4 = VK_FORMAT_R32G32B32A32_UINT;

// A neighbour pass's texel bindings: the grid's cell_start (0), the lists' counts and
// entries (`lists`, lists + 1; shaders/neighbours.glsl) and the arrays it gathers from.
std::vector<vk::TexelBinding> neighbour_texels(uint32_t lists, std::initializer_list<vk::TexelBinding> gathered) {
  std::vector<vk::TexelBinding> t{{0, kUint}, {lists, kUint}, {lists + 1, kUvec4}};
  t.insert(t.end(), gathered);
  return t;
}

// Bad input rather than a Vulkan failure: the scene asks for more than this device holds.
// run.cpp checks the same estimate before any particle is made; this guards every other caller.
uint32_t checked_count(const vk::Context& ctx, const Derived& d, size_t n) {
  check_device_memory(memory_need(d, double(n), &ctx.info(), 0), ctx.info());
  return uint32_t(n);
}
}  // namespace

GpuSolver::GpuSolver(const vk::Context& ctx, const Derived& d, const std::vector<glm::dvec3>& x0)
    : ctx_(ctx),
      d_(d),
      sim_(d.to_gpu(checked_count(ctx, d, x0.size()))),
      n_(sim_.count),
      viscosity_pass_(d.solver.viscosity_pass()),
      vorticity_pass_(d.solver.vorticity > 0),
      correction_pass_(d.solver.method == Method::Ldc),
      lists_(ctx, "neighbour_lists", 5, sizeof(SimConstants), 0,
             std::array<uint32_t, 2>{d.neighbour_capacity, ctx.limits().maxComputeWorkGroupCount[0]},
             std::array<vk::TexelBinding, 2>{{{0, kUint}, {1, kVec4}}}),
      predict_(ctx, "predict", 4, sizeof(SimConstants)),
      velocity_(ctx, "velocity_update", 4, sizeof(SimConstants)),
      density_(neighbour_pass("density", 5, {}, 3, {{1, kVec4}})),
      // The optional passes' programs are built only for a scene that runs them (each
      // neighbour pass is two pipelines, ~5 ms each to create on lavapipe).
      correction_(correction_pass_ ? neighbour_pass("correction_force", 6,
                                                    {d.solver.ldc_clamp ? 1u : 0u,
                                                     std::bit_cast<uint32_t>(float(d.ldc_room)),
                                                     d.solver.ldc_mean_reference ? 1u : 0u},
                                                    4, {{1, kVec4}, {2, kFloat}})
                                   : NeighbourPass{}),
      lambda_(neighbour_pass("constraint_lambda", 6, {}, 4, {{1, kVec4}})),
      smooth_(d.solver.lambda_smoothing > 0 ? neighbour_pass("constraint_smooth", 5, {}, 3, {{1, kVec4}})
                                            : NeighbourPass{}),
      apply_(neighbour_pass("constraint_apply", 6,
                            {std::bit_cast<uint32_t>(d.solver.scorr_k > 0 ? float(d.solver.scorr_n) : 0.0f)}, 4,
                            {{1, kVec4}})),
      viscosity_(viscosity_pass_ ? neighbour_pass("viscosity_vorticity", 8,
                                                  {std::bit_cast<uint32_t>(float(d.solver.damping)),
                                                   std::bit_cast<uint32_t>(float(d.damping_limit)),
                                                   vorticity_pass_ ? 1u : 0u},
                                                  6, {{1, kVec4}, {2, kVec4}})
                                 : NeighbourPass{}),
      vorticity_(vorticity_pass_ ? neighbour_pass("vorticity_force", 6, {}, 4, {{1, kVec4}, {2, kVec4}})
                                 : NeighbourPass{}),
      reduce_(ctx, "reduce_stats", 4, sizeof(SimConstants), kReduceThreads),
      reduce_final_(ctx, "reduce_final", 2, sizeof(ReduceFinalPush), kReduceThreads),
      check_converged_(ctx, "check_converged", 4, sizeof(CheckPush), 1),
      watch_(ctx, "watch", 3, sizeof(SimConstants), 0,
             std::array<uint32_t, 1>{std::bit_cast<uint32_t>(float(d.speed_limit))}),
      grid_(ctx, sim_),
      rho_(ctx, n_ * sizeof(float)),
      neighbour_count_(ctx, (2 * size_t(n_) + 1) * sizeof(uint32_t)),  // counts, then the overflow list
      neighbour_list_(ctx, size_t(n_) * list_words(d.neighbour_capacity) * sizeof(uint32_t)),
      x_lambda_(ctx, n_ * sizeof(glm::vec4)),
      partials_(ctx, 2 * partial_count(n_) * sizeof(glm::vec4)),
      result_(ctx, sizeof(FrameResult), vk::Memory::Host),
      obstacles_(ctx, pack_obstacles(d.obstacles).size() * sizeof(glm::vec4)),
      watch_buf_(ctx, 6 * sizeof(uint32_t)),
      cmd_(ctx),
      timer_(std::make_unique<vk::GpuTimer>(ctx, 2)) {
  for (auto& b : vec4_) b = vk::Buffer(ctx, n_ * sizeof(glm::vec4));
  obstacles_.upload(std::span<const glm::vec4>(pack_obstacles(d.obstacles)));
  if (d.solver.target_compression > 0) {
    check_ = vk::Buffer(ctx, 2 * sizeof(glm::vec4));
    indirect_ = vk::Buffer(ctx, 4 * sizeof(uint32_t));
    overflow_gated_ = vk::Buffer(ctx, 4 * sizeof(uint32_t));
  }
  overflow_groups_ = vk::Buffer(ctx, 4 * sizeof(uint32_t));
  for (auto& b : id_) b = vk::Buffer(ctx, n_ * sizeof(uint32_t));
  // Model no more than the scene needs: vorticity storage only when a pass uses it.
  if (vorticity_pass_) omega_ = vk::Buffer(ctx, n_ * sizeof(glm::vec4));
  if (d.solver.lambda_smoothing > 0) x_lambda_spare_ = vk::Buffer(ctx, n_ * sizeof(glm::vec4));
  ParticleState s;
  s.x = x0;
  s.v.assign(n_, glm::dvec3(0.0));
  s.x_pred = x0;
  upload(s);
}

std::string GpuSolver::device_name() const { return ctx_.info().name; }

void GpuSolver::upload(const ParticleState& s) {
  std::vector<float> rho(n_, 0.0f);
  for (uint32_t i = 0; i < n_ && i < s.rho.size(); ++i) rho[i] = float(s.rho[i]);
  auto pack = [&](const std::vector<glm::dvec3>& a, const std::vector<float>& w) {
    std::vector<glm::vec4> out(n_, glm::vec4(0.0f));
    for (uint32_t i = 0; i < n_ && i < a.size(); ++i) out[i] = glm::vec4(glm::vec3(a[i]), w[i]);
    return out;
  };
  const std::vector<float> zero(n_, 0.0f);
  vec4_[role_[X]].upload(std::span<const glm::vec4>(pack(s.x, zero)));
  vec4_[role_[V]].upload(std::span<const glm::vec4>(pack(s.v, rho)));  // w: the dashpot's rho (velocity_update.comp)
  vec4_[role_[XPred]].upload(std::span<const glm::vec4>(pack(s.x_pred, zero)));
  rho_.upload(std::span<const float>(rho));
  std::vector<uint32_t> ids(n_);
  std::iota(ids.begin(), ids.end(), 0u);
  id_[id_current_].upload(std::span<const uint32_t>(ids));
  density_current_ = false;
  lists_built_ = false;
}

ParticleState GpuSolver::download() const {
  auto ids = id_[id_current_].download<uint32_t>(n_);
  auto unpack3 = [&](const vk::Buffer& b) {
    auto raw = b.download<glm::vec4>(n_);
    std::vector<glm::dvec3> out(n_);
    for (uint32_t i = 0; i < n_; ++i) out[ids[i]] = glm::dvec3(glm::vec3(raw[i]));
    return out;
  };
  auto unpack1 = [&](const std::vector<float>& raw) {
    std::vector<double> out(n_);
    for (uint32_t i = 0; i < n_; ++i) out[ids[i]] = raw[i];
    return out;
  };
  ParticleState s;
  s.x = unpack3(at(X));
  s.v = unpack3(at(V));
  s.x_pred = unpack3(at(XPred));
  if (vorticity_pass_) s.omega = unpack3(omega_);
  s.rho = unpack1(rho_.download<float>(n_));
  std::vector<float> lambda;
  for (const glm::vec4& xl : x_lambda_.download<glm::vec4>(n_)) lambda.push_back(xl.w);
  s.lambda = unpack1(lambda);
  return s;
}

ParticleFrame GpuSolver::read_frame() const {
  return {at(X).download<glm::vec4>(n_), at(V).download<glm::vec4>(n_), rho_.download<float>(n_),
          id_[id_current_].download<uint32_t>(n_)};
}

void GpuSolver::copy_frame(const vk::Buffer& dst) const {
  if (dst.bytes() < frame_bytes(n_)) throw vk::Error("copy_frame: destination buffer too small");
  const VkDeviceSize vec4s = n_ * sizeof(glm::vec4), floats = n_ * sizeof(float);
  ctx_.submit_and_wait([&](VkCommandBuffer cb) {
    vk::memory_barrier(cb);  // the frame's shader writes are visible to the copies
    VkBufferCopy x{0, 0, vec4s}, v{0, vec4s, vec4s}, rho{0, 2 * vec4s, floats};
    vkCmdCopyBuffer(cb, at(X).handle(), dst.handle(), 1, &x);
    vkCmdCopyBuffer(cb, at(V).handle(), dst.handle(), 1, &v);
    vkCmdCopyBuffer(cb, rho_.handle(), dst.handle(), 1, &rho);
    vk::memory_barrier(cb);
  });
}

void GpuSolver::bind_particle_pass(const vk::Program& p) {
  cmd_.set_program(p);
  cmd_.push(sim_);
}

// Every neighbour pass: the grid at binding 0, the lists' counts and entries at `lists`
// and lists + 1 (shaders/neighbours.glsl).
void GpuSolver::bind_neighbours(uint32_t lists) {
  cmd_.bind(0, grid_.cell_start());
  cmd_.bind(lists, neighbour_count_);
  cmd_.bind(lists + 1, neighbour_list_);
}

GpuSolver::NeighbourPass GpuSolver::neighbour_pass(std::string_view shader, uint32_t bindings,
                                                   std::vector<uint32_t> constants, uint32_t lists,
                                                   std::initializer_list<vk::TexelBinding> gathered) const {
  const std::vector<vk::TexelBinding> texels = neighbour_texels(lists, gathered);
  // The shader's own constants, then NEIGHBOUR_CAPACITY and WALK_CELLS (neighbours.glsl).
  constants.push_back(d_.neighbour_capacity);
  auto variant = [&](bool walk_cells) {
    constants.push_back(walk_cells ? 1u : 0u);
    vk::Program p(ctx_, shader, bindings, sizeof(SimConstants), 0, constants, texels);
    constants.pop_back();
    return p;
  };
  return {variant(false), variant(true), lists};
}

void GpuSolver::run_neighbour_pass(const NeighbourPass& pass, const vk::Buffer* indirect,
                                   const std::function<void()>& bind) {
  const bool lists = d_.neighbour_capacity > 0;
  bind_particle_pass(lists ? pass.lists : pass.cells);
  bind_neighbours(pass.lists_binding);
  bind();
  run_particle_pass(indirect);
  if (!lists) return;
  bind_particle_pass(pass.cells);
  bind_neighbours(pass.lists_binding);
  bind();
  cmd_.dispatch_indirect(indirect ? overflow_gated_ : overflow_groups_);
}

void GpuSolver::neighbour_lists(const vk::Buffer& x) {
  if (d_.neighbour_capacity == 0) return;  // no lists: every pass walks the cells
  const uint32_t none[4] = {0, 1, 1, 0};     // the cell walkers' groups (x, y, z)
  cmd_.update(overflow_groups_, none, sizeof none);
  const uint32_t zero = 0;  // the overflow list's length
  cmd_.update(neighbour_count_, &zero, sizeof zero, n_ * sizeof(uint32_t));
  bind_particle_pass(lists_);
  cmd_.bind(0, grid_.cell_start());
  cmd_.bind(1, x);
  cmd_.bind(2, neighbour_count_);
  cmd_.bind(3, neighbour_list_);
  cmd_.bind(4, overflow_groups_);
  cmd_.dispatch(n_);
}

void GpuSolver::grid_at_positions() { sort_by_cells(X, V); }

// v is not carried: velocity_update() recomputes it from x and x_pred.
void GpuSolver::grid_at_predictions() { sort_by_cells(XPred, X); }

void GpuSolver::sort_by_cells(Slot keyed, Slot carried) {
  grid_.build(cmd_, sim_, {&at(keyed), &at(carried), &id_[id_current_]},
              {&at(Spare0), &at(Spare1), &id_[1 - id_current_]});
  swap_roles(keyed, Spare0);
  swap_roles(carried, Spare1);
  id_current_ = 1 - id_current_;
  end_of(PassGroup::Grid);
  neighbour_lists(at(keyed));
  end_of(PassGroup::Lists);
}

void GpuSolver::density() {
  run_neighbour_pass(density_, nullptr, [&] {
    cmd_.bind(1, at(X));
    cmd_.bind(2, rho_);
  });
}

void GpuSolver::correction() {
  run_neighbour_pass(correction_, nullptr, [&] {
    cmd_.bind(1, at(X));
    cmd_.bind(2, rho_);
    cmd_.bind(3, at(V));
  });
}

void GpuSolver::predict() {
  bind_particle_pass(predict_);
  cmd_.bind(0, at(X));
  cmd_.bind(1, at(V));
  cmd_.bind(2, at(XPred));
  cmd_.bind(3, obstacles_);
  cmd_.dispatch(n_);
}

void GpuSolver::run_particle_pass(const vk::Buffer* indirect) {
  if (indirect)
    cmd_.dispatch_indirect(*indirect);
  else
    cmd_.dispatch(n_);
}

void GpuSolver::constraint_lambda(const vk::Buffer* indirect) {
  run_neighbour_pass(lambda_, indirect, [&] {
    cmd_.bind(1, at(XPred));
    cmd_.bind(2, x_lambda_);
    cmd_.bind(3, rho_);
  });
}

void GpuSolver::constraint_smooth(const vk::Buffer* indirect) {
  // Passes go in pairs (the count is even, scene.cpp), so lambda ends where it began.
  for (int pass = 0; pass < d_.solver.lambda_smoothing; ++pass) {
    const bool back = pass % 2;
    run_neighbour_pass(smooth_, indirect, [&] {
      cmd_.bind(1, back ? x_lambda_spare_ : x_lambda_);
      cmd_.bind(2, back ? x_lambda_ : x_lambda_spare_);
    });
  }
}

void GpuSolver::constraint_apply(double relax, const vk::Buffer* indirect) {
  // Jacobi: every particle reads the same x_pred, so the result goes to a spare array.
  sim_.relax = float(relax);
  run_neighbour_pass(apply_, indirect, [&] {
    cmd_.bind(1, x_lambda_);  // x_pred, with lambda beside it
    cmd_.bind(2, at(Spare0));
    cmd_.bind(3, obstacles_);
  });
  swap_roles(XPred, Spare0);
}

void GpuSolver::reduce_measures(const vk::Buffer& into) {
  cmd_.set_program(reduce_);
  cmd_.push(sim_);
  cmd_.bind(0, rho_);
  cmd_.bind(1, at(V));
  cmd_.bind(2, at(X));
  cmd_.bind(3, partials_);
  cmd_.dispatch(n_);
  cmd_.set_program(reduce_final_);
  cmd_.push(ReduceFinalPush{partial_count(n_), n_, sim_.mass});
  cmd_.bind(0, partials_);
  cmd_.bind(1, into);
  cmd_.dispatch(1);
}

void GpuSolver::adaptive_iterations() {
  // Extra iterations come in pairs: constraint_apply swaps two arrays' roles on the host
  // whether or not the GPU runs it, so only an even number keeps x_pred where the host
  // expects it. Each pair runs if check_converged, from the last lambda pass's densities,
  // finds the mean compression above the target.
  const SolverParams& p = d_.solver;
  const auto full = cmd_.groups(n_, lambda_.lists.workgroup_size());
  const uint32_t args[3] = {full[0], full[1], 1};
  cmd_.update(indirect_, args, sizeof args);
  for (int run = p.iterations; run + kAdaptiveStride <= p.max_iterations; run += kAdaptiveStride) {
    reduce_measures(check_);
    cmd_.set_program(check_converged_);
    cmd_.push(CheckPush{float(p.target_compression), full[0], full[1], kAdaptiveStride});
    cmd_.bind(0, check_);
    cmd_.bind(1, indirect_);
    cmd_.bind(2, overflow_groups_);
    cmd_.bind(3, overflow_gated_);
    cmd_.dispatch(1);
    for (const Derived::ConstraintPass& pass : d_.constraint_schedule(kAdaptiveStride)) {
      constraint_lambda(&indirect_);
      if (pass.smoothed) constraint_smooth(&indirect_);
      constraint_apply(pass.relax, &indirect_);
    }
  }
}

void GpuSolver::velocity_update() {
  bind_particle_pass(velocity_);
  cmd_.bind(0, at(X));
  cmd_.bind(1, at(XPred));
  cmd_.bind(2, at(V));
  cmd_.bind(3, rho_);  // into v's w, for viscosity_vorticity
  cmd_.dispatch(n_);
  swap_roles(X, XPred);  // x = x_pred, without a copy
}

void GpuSolver::viscosity_vorticity() {
  run_neighbour_pass(viscosity_, nullptr, [&] {
    cmd_.bind(1, at(X));
    cmd_.bind(2, at(V));
    cmd_.bind(3, at(Spare0));
    // Without vorticity the shader never touches omega (VORTICITY): any buffer fills the slot.
    cmd_.bind(4, vorticity_pass_ ? omega_ : at(Spare0));
    cmd_.bind(5, rho_);
  });
  swap_roles(V, Spare0);
}

void GpuSolver::vorticity_force() {
  run_neighbour_pass(vorticity_, nullptr, [&] {
    cmd_.bind(1, at(X));
    cmd_.bind(2, omega_);
    cmd_.bind(3, at(V));
  });
}

void GpuSolver::end_of(PassGroup group) {
  if (!timing_steps_) return;
  timer_->mark(cmd_);
  segments_.push_back(group);
}

void GpuSolver::record_step() {
  if (correction_pass_) {
    if (!density_current_) {
      density_at_positions();
      end_of(PassGroup::Density);
    }
    correction();
    end_of(PassGroup::Correction);
  }
  predict();
  end_of(PassGroup::Predict);
  grid_at_predictions();
  for (const Derived::ConstraintPass& pass : d_.constraint_schedule(d_.solver.iterations)) {
    constraint_lambda();
    if (pass.smoothed) constraint_smooth();
    constraint_apply(pass.relax);
  }
  if (d_.solver.target_compression > 0) adaptive_iterations();
  end_of(PassGroup::Constraints);
  velocity_update();
  const bool viscosity = viscosity_pass_ || vorticity_pass_;
  if (viscosity) {
    end_of(PassGroup::Velocity);
    if (viscosity_pass_) viscosity_vorticity();
    if (vorticity_pass_) vorticity_force();
  }
  density_current_ = viscosity_pass_;  // the viscosity pass leaves rho at x
  lists_built_ = true;
  watch();
  // The watch counts with the step's last group, so that the groups cover the whole step.
  end_of(viscosity ? PassGroup::Viscosity : PassGroup::Velocity);
}

void GpuSolver::watch() {
  cmd_.update(watch_buf_, &step_in_frame_, sizeof step_in_frame_, 5 * sizeof(uint32_t));
  bind_particle_pass(watch_);
  cmd_.bind(0, at(X));
  cmd_.bind(1, at(V));
  cmd_.bind(2, watch_buf_);
  cmd_.dispatch(n_);
  ++step_in_frame_;
}

void GpuSolver::density_at_positions() {
  // Where the step ran its viscosity pass, that pass summed rho at x already, over the
  // same lists (viscosity_vorticity.comp).
  if (density_current_) return;
  // The last step's lists, built at its x* (docs/design.md step 5: once per step), serve the
  // density at x, as they served its iterations and XSPH: a pair that came within h in
  // the projection adds W(r ~ h) ~ 0 (poly6 is flat there), and a grid build and list
  // pass would cost more than the density itself. Only before the first step after an
  // upload are the particles binned and listed at x.
  if (!lists_built_) grid_at_positions();
  density();
  density_current_ = true;
}

void GpuSolver::record_measures() {
  density_at_positions();
  reduce_measures(result_);
  if (d_.solver.target_compression > 0) {  // the frame's adaptive iteration count, beside the measures
    VkBufferCopy count{INDIRECT_ITERATIONS_WORD * sizeof(uint32_t), offsetof(FrameResult, iterations), sizeof(uint32_t)};
    vkCmdCopyBuffer(cmd_.handle(), indirect_.handle(), result_.handle(), 1, &count);
  }
  VkBufferCopy watch{0, offsetof(FrameResult, watch_flags), 5 * sizeof(uint32_t)};  // and what the watch saw
  vkCmdCopyBuffer(cmd_.handle(), watch_buf_.handle(), result_.handle(), 1, &watch);
  vk::memory_barrier(cmd_.handle());
}

FrameStats GpuSolver::read_measures() const {
  const auto& r = *static_cast<const FrameResult*>(result_.mapped());
  FrameStats s;
  s.mean_compression = r.measures.x;
  s.max_compression = r.measures.y;
  s.kinetic_energy = r.measures.z;
  s.max_speed = r.measures.w;
  s.potential_energy = r.energy.x;
  if (r.watch_flags) s.divergence = {int(r.watch_first_step), r.watch_counts[0], r.watch_counts[1], r.watch_counts[2]};
  return s;
}

FrameStats GpuSolver::advance(int steps) {
  auto start = std::chrono::steady_clock::now();
  // While profiling a step marks the end of each pass group, the grid and lists twice in
  // an ldc step that bins at x (the first after an upload).
  const uint32_t marks = 2 + (profiling_ ? uint32_t(steps) * (kPassGroups + 2) : 0);
  if (timer_->capacity() < marks) timer_ = std::make_unique<vk::GpuTimer>(ctx_, marks);
  segments_.clear();
  begin();
  const uint32_t watch_reset[6] = {0, ~0u, 0, 0, 0, 0};
  cmd_.update(watch_buf_, watch_reset, sizeof watch_reset);
  step_in_frame_ = 0;
  if (d_.solver.target_compression > 0) {
    const uint32_t zero[4] = {0, 0, 0, 0};  // the frame's count of adaptive iterations
    cmd_.update(indirect_, zero, sizeof zero);
  }
  timer_->reset(cmd_);
  timer_->mark(cmd_);
  timing_steps_ = profiling_;
  for (int k = 0; k < steps; ++k) record_step();
  timing_steps_ = false;  // the measures' grid build is not a step's
  const uint32_t end = timer_->mark(cmd_);
  record_measures();
  finish();
  FrameStats s = read_measures();
  if (steps > 0) {
    std::vector<double> t = timer_->read_ms();
    double ms = timer_->available()
                    ? t[end]
                    : std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    s.step_ms = ms / steps;
    s.iterations = d_.solver.iterations;
    if (d_.solver.target_compression > 0)
      s.iterations += double(static_cast<const FrameResult*>(result_.mapped())->iterations) / steps;
    if (timer_->available())
      for (size_t k = 0; k < segments_.size(); ++k) s.pass_ms[size_t(segments_[k])] += (t[k + 1] - t[k]) / steps;
  }
  return s;
}

}  // namespace pbflow
