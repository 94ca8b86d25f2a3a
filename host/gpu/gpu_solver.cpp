#include "gpu/gpu_solver.hpp"

#include <algorithm>
#include <bit>
#include <cstddef>
#include <chrono>
#include <numeric>
#include <stdexcept>

#include "common/input_error.hpp"
#include "gpu/memory_estimate.hpp"
#include "shaders/contract.h"
#include "vk/check.hpp"
#include "vk/context.hpp"

namespace pbflow {

namespace {

// coarse_sweep.comp in one workgroup of this many threads, phi in its shared memory, while the
// grid's phi (this many nodes, this many of a colour) fits there, or 0: a dispatch a half sweep.
// One workgroup saves the dispatches' barriers. A CPU device takes every invocation through
// every barrier: there a thread for eight nodes. Both measured: docs/performance.md,
// "Measurements behind the code".
uint32_t coarse_sweep_group(const vk::Context& ctx, uint32_t nodes, uint32_t per_colour) {
  if (nodes * sizeof(float) > ctx.limits().maxComputeSharedMemorySize) return 0;
  const bool cpu = ctx.info().kind == "cpu";
  const uint32_t most = std::min(1024u, ctx.limits().maxComputeWorkGroupInvocations) / 64 * 64;
  const uint32_t wanted = cpu ? per_colour / 8 : per_colour;
  return std::clamp((wanted + 63) / 64 * 64, 64u, most);
}

// The near readers' VkDispatchIndirectCommand in the lists' dispatch buffer (neighbour_lists.comp).
constexpr VkDeviceSize kNearGroupsOffset = NEAR_GROUPS_WORD * sizeof(uint32_t);

struct ReduceFinalPush {
  uint32_t partial_count, particle_count;
  float mass;
};

struct CheckPush {  // check_converged.comp
  float target;
  uint32_t full_x, full_y, per_check;
};

// Bad input rather than a Vulkan failure: the scene asks for more than this device holds (run.cpp
// checks the same estimate before any particle is made; this guards every other caller).
uint32_t checked_count(const vk::Context& ctx, const Derived& d, size_t n) {
  check_device_memory(memory_need(d, double(n), &ctx.info()), ctx.info());
  return uint32_t(n);
}
}  // namespace

GpuSolver::GpuSolver(const vk::Context& ctx, const Derived& d, const std::vector<glm::dvec3>& x0,
                     std::optional<GpuLayout> layout)
    : ctx_(ctx),
      d_(d),
      sim_(d.to_gpu(checked_count(ctx, d, x0.size()))),
      keys_(d),
      n_(sim_.count),
      layout_(layout.value_or(GpuLayout::for_device(ctx.info()))),
      plan_(plan_buffers(d, d.capacity_for(n_))),
      viscosity_pass_(d.solver.viscosity_pass()),
      vorticity_pass_(d.solver.vorticity > 0),
      correction_pass_(d.solver.method == Method::Ldc),
      lists_(lists_program(false)),
      near_lists_(near_variant() ? lists_program(true) : vk::Program{}),
      predict_(particle_program("predict")),
      velocity_(particle_program("velocity_update")),
      density_(neighbour_pass("density", {})),
      // The optional passes' programs are built only for a scene that runs them: each
      // neighbour pass is two pipelines, and a pipeline takes milliseconds to create.
      correction_(correction_pass_ ? neighbour_pass("correction_force", {{"LDC_ROOM", float(d.ldc_room)}})
                                   : NeighbourPass{}),
      lambda_(neighbour_pass("constraint_lambda", {})),
      smooth_(d.smooths_lambda() ? neighbour_pass("constraint_smooth", {}) : NeighbourPass{}),
      apply_(neighbour_pass("constraint_apply", {})),
      viscosity_(viscosity_pass_
                     ? neighbour_pass("viscosity_vorticity", {{"DAMPING_LIMIT", float(d.damping_limit)}})
                     : NeighbourPass{}),
      vorticity_(vorticity_pass_ ? neighbour_pass("vorticity_force", {}) : NeighbourPass{}),
      reduce_(particle_program("reduce_stats", {}, kReduceThreads)),
      reduce_final_(ctx, "reduce_final", sizeof(ReduceFinalPush), kReduceThreads),
      check_converged_(ctx, "check_converged", sizeof(CheckPush), 1),
      watch_(particle_program("watch", std::array<vk::Constant, 1>{{{"SPEED_LIMIT", float(d.speed_limit)}}})),
      grid_(ctx, plan_.grid),
      rho_(ctx, plan_.rho),
      neighbour_count_(ctx, plan_.neighbour_count),
      neighbour_list_(ctx, plan_.neighbour_list),
      x_lambda_(ctx, plan_.particle_vec4),
      partials_(ctx, plan_.partials),
      result_(ctx, plan_.result, vk::Memory::Host),
      obstacles_(ctx, plan_.obstacles),
      work_(ctx, plan_.work), crease_records_(ctx, plan_.crease_records),
      overflow_groups_(ctx, plan_.overflow_groups),
      watch_buf_(ctx, plan_.watch),
      cmd_(ctx),
      timer_(std::make_unique<vk::GpuTimer>(ctx, 2)) {
  for (auto& b : vec4_) b = vk::Buffer(ctx, plan_.particle_vec4);
  for (auto& b : id_) b = vk::Buffer(ctx, plan_.id);
  for (auto& b : distances_) b = vk::Buffer(ctx, plan_.distances);
  obstacles_.upload(std::span<const glm::vec4>(pack_obstacles(d.obstacles, d.keep_out)));
  // Model no more than the scene needs: the plan leaves out what its passes never use.
  if (plan_.adaptive_words)
    for (vk::Buffer* b : {&check_, &indirect_, &overflow_gated_}) *b = vk::Buffer(ctx, plan_.adaptive_words);
  if (plan_.curl) curl_ = vk::Buffer(ctx, plan_.curl);
  if (plan_.x_lambda_spare) x_lambda_spare_ = vk::Buffer(ctx, plan_.x_lambda_spare);
  if (d.coarse.strength > 0) build_coarse();
  if (!d.drains.empty()) build_drains();
  if (!d.bodies.empty()) build_bodies();
  capacity_ = d.capacity_for(n_), next_id_ = n_;  // the Solver's
  upload({x0, std::vector<glm::dvec3>(n_, glm::dvec3(0.0)), x0, {}, {}, {}, {}});
}

// The drains' programs and buffers, where the scene has drains.
void GpuSolver::build_drains() {
  drain_mark_ = particle_program("drain_mark", std::array<vk::Constant, 1>{{{"DRAINS", int(d_.drains.size())}}});
  drain_compact_ = particle_program("drain_compact");
  drains_ = vk::Buffer(ctx_, plan_.drains);
  std::vector<glm::vec4> boxes;
  for (const Drain& b : d_.drains) boxes.insert(boxes.end(), {glm::vec4(glm::vec3(b.min), 0.0f), glm::vec4(glm::vec3(b.max), 0.0f)});
  drains_.upload(std::span<const glm::vec4>(boxes));
  drained_ = vk::Buffer(ctx_, plan_.drained);
  drain_counts_ = vk::Buffer(ctx_, plan_.drain_counts);
  drain_keep_ = GpuScan(ctx_, plan_.drain_keep);
}

// The coarse correction's programs and node buffers, where the scene runs it.
void GpuSolver::build_coarse() {
  const Derived::Coarse& c = d_.coarse;
  std::vector<vk::Constant> grid = {{"NODES_X", uint32_t(c.nodes.x)},
                                    {"NODES_Y", uint32_t(c.nodes.y)},
                                    {"NODES_Z", uint32_t(c.nodes.z)},
                                    {"CELL_X", float(c.cell.x)},
                                    {"CELL_Y", float(c.cell.y)},
                                    {"CELL_Z", float(c.cell.z)}};
  coarse_deposit_ = particle_program("coarse_deposit", grid);
  coarse_prepare_ = particle_program("coarse_prepare", grid);
  coarse_gradient_ = particle_program("coarse_gradient", grid);
  auto sweep = [&](uint32_t threads, uint32_t first_colour, uint32_t shared_nodes) {
    std::vector<vk::Constant> k = grid;
    k.insert(k.end(), {{"FIRST_COLOUR", int(first_colour)}, {"SHARED_NODES", int(shared_nodes)}});
    return particle_program("coarse_sweep", k, threads);
  };
  coarse_sweep_threads_ = coarse_sweep_group(ctx_, uint32_t(c.count()), uint32_t(c.per_colour()));
  if (coarse_sweep_threads_) {
    coarse_sweeps_.push_back(sweep(coarse_sweep_threads_, 0, uint32_t(c.count())));
  } else {
    coarse_sweeps_.push_back(sweep(0, 0, 0));
    coarse_sweeps_.push_back(sweep(0, 1, 0));
  }
  grid.push_back({"STRENGTH", float(c.strength)});
  coarse_apply_ = particle_program("coarse_apply", grid);
  coarse_sums_ = vk::Buffer(ctx_, plan_.coarse_sums);
  coarse_phi_ = vk::Buffer(ctx_, plan_.coarse_phi);
  coarse_grad_ = vk::Buffer(ctx_, plan_.coarse_grad);
  coarse_open_ = vk::Buffer(ctx_, plan_.coarse_open);
  coarse_open_.upload(std::span<const float>(c.open));
}

std::string GpuSolver::device_name() const { return ctx_.info().name; }

void GpuSolver::carry(const SolidsState& s) {
  carry_clocks(s, d_.dt);
  d_.carry_solids(s.obstacles, s.tank, s.bodies);
  obstacles_.upload(std::span<const glm::vec4>(pack_obstacles(d_.obstacles, d_.keep_out)));
  if (!d_.coarse.open.empty()) coarse_open_.upload(std::span<const float>(d_.coarse.open));
}

void GpuSolver::upload(const ParticleState& s) {
  if (s.x.size() > capacity_) throw std::invalid_argument("upload: more particles than the solver's capacity");
  n_ = sim_.count = uint32_t(s.x.size());
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
  if (d_.coarse.strength > 0)  // the coarse solve starts from its last solution: a new state, from 0
    coarse_phi_.upload(std::span<const float>(std::vector<float>(size_t(d_.coarse.count()), 0.0f)));
  std::vector<uint32_t> ids(s.id.begin(), s.id.begin() + std::min(s.id.size(), size_t(n_)));
  if (ids.size() < n_) {
    ids.resize(n_);
    std::iota(ids.begin(), ids.end(), 0u);
  }
  if (n_ > 0) next_id_ = std::max(next_id_, *std::max_element(ids.begin(), ids.end()) + 1);
  id_[id_current_].upload(std::span<const uint32_t>(ids));
  density_current_ = false;
  lists_built_ = false;
  smoothed_current_ = false;
}

ParticleState GpuSolver::download() const {
  const auto ids = id_[id_current_].download<uint32_t>(n_);
  const std::vector<size_t> order = ascending_ids(ids);
  auto unpack3 = [&](const vk::Buffer& b) {
    auto raw = b.download<glm::vec4>(n_);
    std::vector<glm::dvec3> out(n_);
    for (uint32_t k = 0; k < n_; ++k) out[k] = glm::dvec3(glm::vec3(raw[order[k]]));
    return out;
  };
  auto unpack1 = [&](const std::vector<float>& raw) {
    std::vector<double> out(n_);
    for (uint32_t k = 0; k < n_; ++k) out[k] = raw[order[k]];
    return out;
  };
  ParticleState s;
  for (size_t k : order) s.id.push_back(ids[k]);
  s.x = unpack3(at(X));
  s.v = unpack3(at(V));
  s.x_pred = unpack3(at(XPred));
  if (vorticity_pass_) s.curl = unpack3(curl_);
  s.rho = unpack1(rho_.download<float>(n_));
  std::vector<float> lambda;
  for (const glm::vec4& xl : x_lambda_.download<glm::vec4>(n_)) lambda.push_back(xl.w);
  s.lambda = unpack1(lambda);
  return s;
}

ParticleFrame GpuSolver::read_frame() const {
  ParticleFrame f{at(X).download<glm::vec4>(n_),
                  at(V).download<glm::vec4>(n_),
                  rho_.download<float>(n_),
                  id_[id_current_].download<uint32_t>(n_),
                  smoothed_current_ ? at(Spare0).download<glm::vec4>(n_) : std::vector<glm::vec4>{},
                  smoothed_current_ ? shape_.download<glm::vec4>(2 * n_) : std::vector<glm::vec4>{},
                  {},
                  {}};
  add_white_water(f, white_water());
  return f;
}

void GpuSolver::set_outputs(FrameOutputs outputs) {
  outputs = outputs_made(d_, outputs);
  const bool white_was_on = outputs_.white_water;
  outputs_ = outputs;
  if (outputs.surface && positions_.lists.pipeline() == VK_NULL_HANDLE) positions_ = neighbour_pass("smoothed_positions", {});
  if (outputs.white_water && white_advect_.pipeline() == VK_NULL_HANDLE) {
    white_emit_ = neighbour_pass("white_water_emit", {{"FLOW_SPEED", float(d_.flow_speed)}});
    white_advect_ = particle_program("white_water_advect");
    white_compact_ = particle_program("white_water_compact");
    white_birth_ = particle_program("white_water_birth", std::array<vk::Constant, 1>{{{"SPACING", float(d_.spacing)}}});
  }
  // The plan's buffers for these outputs, and none for those off.
  const SolverBuffers plan = plan_buffers(d_, capacity_, outputs);
  if (shape_.bytes() != plan.shape) shape_ = plan.shape ? vk::Buffer(ctx_, plan.shape) : vk::Buffer{};
  if (white_was_on == outputs.white_water) return;
  white_count_ = plan.white_count ? vk::Buffer(ctx_, plan.white_count) : vk::Buffer{};
  for (int k = 0; k < SolverBuffers::kWhiteLists; ++k) {
    white_x_[k] = plan.white_array ? vk::Buffer(ctx_, plan.white_array) : vk::Buffer{};
    white_v_[k] = plan.white_array ? vk::Buffer(ctx_, plan.white_array) : vk::Buffer{};
  }
  white_survivors_ = outputs.white_water ? GpuScan(ctx_, plan.white_survivors) : GpuScan{};
  white_births_ = outputs.white_water ? GpuScan(ctx_, plan.white_births) : GpuScan{};
  upload_white_water({});
}

void GpuSolver::smoothed_positions() {
  run_neighbour_pass(positions_, nullptr, [&] {
    cmd_.bind("obstacles", obstacles_);  // the solids' mirrors (solids.glsl)
    cmd_.bind("x", at(X));
    cmd_.bind("x_smooth", at(Spare0));
    cmd_.bind("shape", shape_);
  });
  smoothed_current_ = true;
}

void GpuSolver::copy_frame(const vk::Buffer& dst) const {
  const size_t white = white_water_capacity();
  if (dst.bytes() < frame_bytes(n_, white)) throw vk::Error("copy_frame: destination buffer too small");
  const FrameOffsets to = frame_offsets(n_, white);
  ctx_.submit_and_wait([&](VkCommandBuffer cb) {
    auto copy = [&](const vk::Buffer& from, size_t offset, size_t next) {
      const VkBufferCopy region{0, offset, next - offset};
      vkCmdCopyBuffer(cb, from.handle(), dst.handle(), 1, &region);
    };
    vk::memory_barrier(cb);  // the frame's shader writes are visible to the copies
    copy(at(X), to.x, to.v);
    copy(at(V), to.v, to.rho);
    copy(rho_, to.rho, to.x_smooth);
    // Without smoothed positions (not asked for, or before the first frame), x stands in, and
    // zeros draw spheres.
    copy(smoothed_current_ ? at(Spare0) : at(X), to.x_smooth, to.shape);
    if (smoothed_current_)
      copy(shape_, to.shape, to.white_count);
    else
      vkCmdFillBuffer(cb, dst.handle(), to.shape, to.white_count - to.shape, 0);
    // white_header(0), or its words after the count where the count is copied in: no two
    // transfers write the same bytes, as nothing orders them.
    const auto header = white_header(0);
    static_assert(sizeof(header) == WHITE_HEADER_BYTES);
    const size_t skip = outputs_.white_water ? sizeof(uint32_t) : 0;
    vkCmdUpdateBuffer(cb, dst.handle(), to.white_count + skip, WHITE_HEADER_BYTES - skip, header.data() + skip / sizeof(uint32_t));
    if (outputs_.white_water) {
      copy(white_count_, to.white_count, to.white_count + sizeof(uint32_t));
      copy(white_x_[0], to.white_x, to.white_v);
      copy(white_v_[0], to.white_v, to.end);
    }
    vk::memory_barrier(cb);
  });
}

void GpuSolver::bind_particle_pass(const vk::Program& p) {
  cmd_.set_program(p);
  cmd_.push(sim_);
}

// Every neighbour pass reads the grid and the lists (shaders/neighbours.glsl).
void GpuSolver::bind_neighbours() {
  if (cmd_.reads("crease_records")) cmd_.bind("crease_records", crease_records_);  // not a pass blind to the solids
  if (cmd_.reads("distances")) cmd_.bind("distances", distances_[distances_current_]);
  cmd_.bind("cell_start", grid_.cell_start());
  cmd_.bind("neighbour_count", neighbour_count_);
  cmd_.bind("neighbour_list", neighbour_list_);
}

vk::Program GpuSolver::particle_program(std::string_view shader, std::span<const vk::Constant> constants,
                                        uint32_t workgroup_size) const {
  return vk::Program(ctx_, shader, sizeof(SimConstants), workgroup_size, constants, keys_.constants());
}

GpuSolver::NeighbourPass GpuSolver::neighbour_pass(std::string_view shader, std::vector<vk::Constant> constants) const {
  constants.push_back({"NEIGHBOUR_CAPACITY", d_.neighbour_capacity});
  auto variant = [&](bool walk_cells, bool obstacle_mirrors) {
    constants.push_back({"WALK_CELLS", walk_cells});
    constants.push_back({"OBSTACLE_MIRRORS", obstacle_mirrors});
    vk::Program p = particle_program(shader, constants);
    constants.erase(constants.end() - 2, constants.end());
    return p;
  };
  return {variant(false, false), near_readers() ? variant(false, true) : vk::Program{}, variant(true, true)};
}

void GpuSolver::run_neighbour_pass(const NeighbourPass& pass, const vk::Buffer* indirect,
                                   const std::function<void()>& bind) {
  auto use = [&](const vk::Program& p) {
    bind_particle_pass(p);
    bind_neighbours();
    bind();
  };
  if (d_.neighbour_capacity == 0) {
    use(pass.cells);
    return run_particle_pass(indirect);
  }
  const vk::Buffer& listed = indirect ? overflow_gated_ : overflow_groups_;  // the two lists' dispatches
  cmd_.disjoint([&] {
    use(pass.lists);
    run_particle_pass(indirect);
    if (pass.near.pipeline() != VK_NULL_HANDLE) {
      use(pass.near);
      cmd_.dispatch_indirect(listed, kNearGroupsOffset);
    }
    use(pass.cells);
    cmd_.dispatch_indirect(listed);
  });
}

bool GpuSolver::near_readers() const { return d_.neighbour_capacity > 0 && !d_.obstacles.empty(); }
bool GpuSolver::walk_lists_near() const { return layout_.near_in_walk && near_readers(); }
bool GpuSolver::near_variant() const { return !d_.obstacles.empty() && !walk_lists_near(); }

vk::Program GpuSolver::lists_program(bool near) const {
  const bool near_in_walk = !near && walk_lists_near();
  const std::array<vk::Constant, 4> constants{{
      {"NEIGHBOUR_CAPACITY", d_.neighbour_capacity},
      {"MAX_GROUPS_X", ctx_.limits().maxComputeWorkGroupCount[0]},
      {"OBSTACLE_MIRRORS", near || near_in_walk},
      {"NEAR_IN_WALK", near_in_walk},
  }};
  return particle_program("neighbour_lists", constants);
}

void GpuSolver::neighbour_lists(const vk::Buffer& x) {
  // No lists: every pass walks the cells; the near variant runs only for a mesh's creases, if any.
  const bool lists = d_.neighbour_capacity > 0;
  if (!lists && !any_mesh(d_.obstacles)) return;
  auto bind = [&](const vk::Program& p) {
    bind_particle_pass(p);
    cmd_.bind("cell_start", grid_.cell_start());
    cmd_.bind("x", x);
    cmd_.bind("neighbour_count", neighbour_count_);
    cmd_.bind("neighbour_list", neighbour_list_);
    cmd_.bind("overflow_groups", overflow_groups_);
    cmd_.bind("obstacles", obstacles_);
    cmd_.bind("crease_records", crease_records_);
    cmd_.bind("distances_out", distances_[distances_current_]);
  };
  if (lists) {
    const uint32_t none[2 * NEAR_GROUPS_WORD] = {0, 1, 1, 0, 0, 1, 1, 0};  // the cell walkers' and the near readers' groups
    cmd_.update(overflow_groups_, none, sizeof none);
    const uint32_t zero[2] = {0, 0};  // the overflow list's length and the near list's
    cmd_.update(neighbour_count_, zero, sizeof zero, n_ * sizeof(uint32_t));
    bind(lists_);
    cmd_.dispatch(n_);
  }
  if (!near_variant()) return;
  bind(near_lists_);  // the images of the particles near obstacles, their meshes' creases
  if (lists)
    cmd_.dispatch_indirect(overflow_groups_, kNearGroupsOffset);
  else
    cmd_.dispatch(n_);
}

void GpuSolver::grid_at_positions() {
  sort_by_cells(X, V);
  neighbour_lists(at(X));
}

// v is not carried: velocity_update() recomputes it from x and x_pred.
void GpuSolver::grid_at_predictions() {
  sort_by_cells(XPred, X);
  neighbour_lists(at(XPred));
}

void GpuSolver::sort_by_cells(Slot keyed, Slot carried) {
  grid_.build(cmd_, sim_, {&at(keyed), &at(carried), &id_[id_current_]},
              {&at(Spare0), &at(Spare1), &id_[1 - id_current_]});
  swap_roles(keyed, Spare0);
  swap_roles(carried, Spare1);
  id_current_ = 1 - id_current_;
}

void GpuSolver::density() {
  run_neighbour_pass(density_, nullptr, [&] {
    cmd_.bind("obstacles", obstacles_);  // the solids' mirrors (solids.glsl)
    cmd_.bind("x", at(X));
    cmd_.bind("rho", rho_);
  });
}

void GpuSolver::correction_and_predict() {
  run_neighbour_pass(correction_, nullptr, [&] {
    cmd_.bind("obstacles", obstacles_);  // the solids' mirrors (solids.glsl)
    cmd_.bind("x", at(X));
    cmd_.bind("rho", rho_);
    cmd_.bind("v", at(V));
    cmd_.bind("x_pred", at(XPred));
    cmd_.bind("work", work_);
    cmd_.bind("body_pushes", body_pushes());
  });
}

void GpuSolver::predict() {
  bind_particle_pass(predict_);
  cmd_.bind("x", at(X));
  cmd_.bind("v", at(V));
  cmd_.bind("x_pred", at(XPred));
  cmd_.bind("obstacles", obstacles_);
  cmd_.bind("work", work_);
  cmd_.bind("body_pushes", body_pushes());
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
    cmd_.bind("obstacles", obstacles_);  // the solids' mirrors (solids.glsl)
    cmd_.bind("x_pred", at(XPred));
    cmd_.bind("x_lambda", x_lambda_);
    cmd_.bind("rho", rho_);
  });
}

void GpuSolver::constraint_smooth(const vk::Buffer* indirect) {
  // Passes go in pairs (the count is even, scene.cpp), so lambda ends where it began.
  for (int pass = 0; pass < d_.solver.lambda_smoothing; ++pass) {
    const bool back = pass % 2;
    run_neighbour_pass(smooth_, indirect, [&] {
      cmd_.bind("obstacles", obstacles_);  // the solids' mirrors (solids.glsl)
      cmd_.bind("x_lambda_in", back ? x_lambda_spare_ : x_lambda_);
      cmd_.bind("x_lambda_out", back ? x_lambda_ : x_lambda_spare_);
    });
  }
}

void GpuSolver::constraint_apply(double relaxation, const vk::Buffer* indirect) {
  // Jacobi: every particle reads the same x_pred, so the result goes to a spare array.
  sim_.relaxation = float(relaxation);
  run_neighbour_pass(apply_, indirect, [&] {
    cmd_.bind("obstacles", obstacles_);  // the solids' mirrors (solids.glsl)
    cmd_.bind("x_lambda", x_lambda_);  // x_pred, with lambda beside it
    cmd_.bind("x_out", at(Spare0));
    cmd_.bind("distances_out", distances_[1 - distances_current_]);
    cmd_.bind("work", work_);
    cmd_.bind("body_pushes", body_pushes());
  });
  swap_roles(XPred, Spare0);
  distances_current_ = 1 - distances_current_;
}

void GpuSolver::coarse_correction() {
  cmd_.fill(coarse_sums_, 0);
  bind_particle_pass(coarse_deposit_);
  cmd_.bind("x_pred", at(XPred));
  cmd_.bind("rho", rho_);
  cmd_.bind("sums", coarse_sums_);
  cmd_.dispatch(n_);
  const uint32_t nodes = uint32_t(d_.coarse.count()), per_colour = uint32_t(d_.coarse.per_colour());
  bind_particle_pass(coarse_prepare_);
  cmd_.bind("sums", coarse_sums_);
  cmd_.bind("phi", coarse_phi_);
  cmd_.bind("open", coarse_open_);
  cmd_.dispatch(nodes);
  // All the sweeps in one workgroup, or a dispatch per half sweep (coarse_sweep_group).
  for (int sweep = 0; sweep < (coarse_sweep_threads_ ? 1 : COARSE_SWEEPS); ++sweep)
    for (const vk::Program& half : coarse_sweeps_) {
      bind_particle_pass(half);
      cmd_.bind("sums", coarse_sums_);
      cmd_.bind("phi", coarse_phi_);
      cmd_.dispatch(coarse_sweep_threads_ ? coarse_sweep_threads_ : per_colour);
    }
  bind_particle_pass(coarse_gradient_);
  cmd_.bind("sums", coarse_sums_);
  cmd_.bind("phi", coarse_phi_);
  cmd_.bind("grad", coarse_grad_);
  cmd_.dispatch(nodes);
  if (!d_.bodies.empty()) body_water_line();  // x_pred before the correction moves it
  bind_particle_pass(coarse_apply_);
  cmd_.bind("x_lambda", x_lambda_);
  cmd_.bind("distances_out", distances_[distances_current_]);  // in place, as x_lambda
  cmd_.bind("grad", coarse_grad_);
  cmd_.bind("phi", coarse_phi_);
  cmd_.bind("obstacles", obstacles_);
  cmd_.bind("work", work_);
  cmd_.bind("body_pushes", body_pushes());
  cmd_.dispatch(n_);
}

void GpuSolver::reduce_measures(const vk::Buffer& into) {
  cmd_.set_program(reduce_);
  cmd_.push(sim_);
  cmd_.bind("rho", rho_);
  cmd_.bind("v", at(V));
  cmd_.bind("x", at(X));
  cmd_.bind("work", work_);
  cmd_.bind("partials", partials_);
  cmd_.dispatch(n_);
  cmd_.set_program(reduce_final_);
  cmd_.push(ReduceFinalPush{uint32_t(partial_count(n_)), n_, sim_.mass});
  cmd_.bind("partials", partials_);
  cmd_.bind("result", into);
  cmd_.dispatch(1);
}

void GpuSolver::adaptive_iterations() {
  // Extra iterations come kAdaptiveStride at a time (sim/step_plan.hpp says why). Each
  // group runs if check_converged, from the last lambda pass's densities, finds the mean
  // compression above the target.
  const SolverParams& p = d_.solver;
  const auto full = cmd_.groups(n_, lambda_.lists.workgroup_size());
  const uint32_t args[3] = {full[0], full[1], 1};
  cmd_.update(indirect_, args, sizeof args);
  const std::vector<PlannedPass> group = constraint_plan(d_, kAdaptiveStride, false);
  for (int run = p.iterations; run + kAdaptiveStride <= p.max_iterations; run += kAdaptiveStride) {
    reduce_measures(check_);
    cmd_.set_program(check_converged_);
    cmd_.push(CheckPush{float(p.target_compression), full[0], full[1], kAdaptiveStride});
    cmd_.bind("measure", check_);
    cmd_.bind("indirect", indirect_);
    cmd_.bind("overflow", overflow_groups_);
    cmd_.bind("overflow_gated", overflow_gated_);
    cmd_.dispatch(1);
    for (const PlannedPass& pass : group) record(pass, &indirect_);
  }
}

void GpuSolver::velocity_update() {
  bind_particle_pass(velocity_);
  cmd_.bind("x", at(X));
  cmd_.bind("x_pred", at(XPred));
  cmd_.bind("v", at(V));
  cmd_.bind("rho", rho_);  // into v's w, for viscosity_vorticity
  cmd_.bind("obstacles", obstacles_);  // the tank's kick, for its work
  cmd_.bind("work", work_);
  cmd_.dispatch(n_);
  swap_roles(X, XPred);  // x = x_pred, without a copy
}

void GpuSolver::viscosity_vorticity() {
  run_neighbour_pass(viscosity_, nullptr, [&] {
    cmd_.bind("obstacles", obstacles_);  // the solids' mirrors (solids.glsl)
    cmd_.bind("x", at(X));
    cmd_.bind("v_rho", at(V));
    cmd_.bind("v_out", at(Spare0));
    // Without vorticity the shader never touches the curl (VORTICITY): any buffer fills the slot.
    cmd_.bind("curl", vorticity_pass_ ? curl_ : at(Spare0));
    cmd_.bind("rho", rho_);
    cmd_.bind("work", work_);
    cmd_.bind("body_pushes", body_pushes());
  });
  swap_roles(V, Spare0);
}

void GpuSolver::vorticity_force() {
  run_neighbour_pass(vorticity_, nullptr, [&] {
    cmd_.bind("x", at(X));
    cmd_.bind("curl", curl_);
    cmd_.bind("v", at(V));
  });
}

void GpuSolver::record(const PlannedPass& p, const vk::Buffer* indirect) {
  switch (p.pass) {
    case Pass::Move: move_solids(); break;
    case Pass::Density: density_at_positions(); break;
    case Pass::CorrectionPredict: correction_and_predict(), answer_bodies(p.pass); break;
    case Pass::Predict: predict(), answer_bodies(p.pass); break;
    case Pass::Grid: sort_by_cells(XPred, X); break;  // v is not carried: the velocity pass recomputes it
    case Pass::Lists: neighbour_lists(at(XPred)), lists_built_ = true; break;
    case Pass::Lambda: constraint_lambda(indirect); break;
    case Pass::Coarse: coarse_correction(), answer_bodies(p.pass); break;
    case Pass::Smooth: constraint_smooth(indirect); break;
    case Pass::Apply: constraint_apply(p.relaxation, indirect), answer_bodies(p.pass); break;
    case Pass::Adaptive: adaptive_iterations(); break;
    case Pass::Velocity:
      velocity_update(), density_current_ = false;
      if (!solids_held_) bodies_.finish(d_);
      break;
    case Pass::Viscosity: viscosity_vorticity(), density_current_ = true, answer_bodies(p.pass); break;  // it sums rho at x
    case Pass::Vorticity: vorticity_force(); break;
    case Pass::Watch: watch(); break;
    case Pass::Measures: record_measures(); break;
    case Pass::Surface: smoothed_positions(); break;
    case Pass::WhiteWaterAdvect: white_water_advect(frame_time_); break;
    case Pass::WhiteWaterEmit: white_water_emit(frame_time_, frames_advanced_); break;
  }
}

void GpuSolver::relax() {
  const bool held = std::exchange(solids_held_, true);  // no time passes: the bodies stay
  begin();
  const VkBufferCopy all{0, 0, at(X).bytes()};
  vkCmdCopyBuffer(cmd_.handle(), at(X).handle(), at(XPred).handle(), 1, &all);  // x* = x
  vk::memory_barrier(cmd_.handle());
  for (const PlannedPass& pass : relaxation_plan(d_)) record(pass);
  swap_roles(X, XPred);
  cmd_.fill(at(V), 0);  // the sort left v in the old order: it is zero anyway
  finish();
  solids_held_ = held;
  density_current_ = false;  // no pass summed rho at the new x
  smoothed_current_ = false;
}

// The moving solids' poses (the obstacles' header) and, with the coarse correction, the nodes'
// open shares, recorded into the frame's commands: the host knows every step's time.
void GpuSolver::move_solids() {
  bool open_changed = false;
  if (solids_held_)
    d_.hold_solids();
  else
    open_changed = step_solids(d_, bodies_, double(++steps_moved_) * d_.dt);
  update_obstacle_header();
  if (open_changed) cmd_.update(coarse_open_, d_.coarse.open.data(), uint32_t(d_.coarse.open.size() * sizeof(float)));
}

void GpuSolver::update_obstacle_header() {
  const std::vector<glm::vec4> header = pack_obstacle_header(d_.obstacles, d_.keep_out, d_.tank_kick);
  cmd_.update(obstacles_, header.data(), uint32_t(header.size() * sizeof(glm::vec4)));
}

void GpuSolver::watch() {
  cmd_.update(watch_buf_, &step_in_frame_, sizeof step_in_frame_, offsetof(WatchWords, step));
  bind_particle_pass(watch_);
  cmd_.bind("x", at(X));
  cmd_.bind("v", at(V));
  cmd_.bind("watch", watch_buf_);
  cmd_.dispatch(n_);
  ++step_in_frame_;
}

void GpuSolver::density_at_positions() {
  // Where the step ran its viscosity pass, that pass summed rho at x already, over the
  // same lists (viscosity_vorticity.comp).
  if (density_current_) return;
  // The last step's lists, built at its x* (once per step), serve the
  // density at x, as they served its iterations and XSPH: a pair that came within h in
  // the projection adds W(r ~ h) ~ 0 (poly6 is flat there), and a grid build and list
  // pass would cost more than the density itself. Only before the first step after an
  // upload are the particles binned and listed at x.
  if (!lists_built_) grid_at_positions();
  density();
  density_current_ = true;
}

void GpuSolver::record_measures() {
  reduce_measures(result_);
  if (d_.solver.target_compression > 0) {  // the frame's adaptive iteration count, beside the measures
    VkBufferCopy count{INDIRECT_ITERATIONS_WORD * sizeof(uint32_t), offsetof(FrameResult, iterations), sizeof(uint32_t)};
    vkCmdCopyBuffer(cmd_.handle(), indirect_.handle(), result_.handle(), 1, &count);
  }
  VkBufferCopy watch{0, offsetof(FrameResult, watch), sizeof(WatchWords)};  // and what the watch saw
  vkCmdCopyBuffer(cmd_.handle(), watch_buf_.handle(), result_.handle(), 1, &watch);
  vk::memory_barrier(cmd_.handle());
}

FrameStats GpuSolver::read_measures() const {
  const auto& r = *static_cast<const FrameResult*>(result_.mapped());
  FrameStats s;
  s.mean_compression = r.mean_compression;
  s.max_compression = r.max_compression;
  s.kinetic_energy = r.kinetic_energy;
  s.max_speed = r.max_speed;
  s.potential_energy = r.potential_energy;
  s.solid_work = r.solid_work;
  s.body_energy = BodyCoupling::energy(d_);
  const WatchWords& w = r.watch;
  if (w.flags) s.divergence = {int(w.first_step), w.counts[0], w.counts[1], w.counts[2]};
  return s;
}

void GpuSolver::record_timed(const std::vector<PlannedPass>& plan) {
  std::vector<bool> ends(plan.size());
  for (size_t k = 0; k < plan.size(); ++k) {
    const PassGroup group = plan[k].group, next = k + 1 < plan.size() ? plan[k + 1].group : group;
    ends[k] = k + 1 == plan.size() || (next != group && (profiling_ || !in_step(group) || !in_step(next)));
  }
  const uint32_t marks = 1 + uint32_t(std::count(ends.begin(), ends.end(), true));
  if (timer_->capacity() < marks) timer_ = std::make_unique<vk::GpuTimer>(ctx_, marks);
  segments_.clear();
  timer_->reset(cmd_);
  timer_->mark(cmd_);
  for (size_t k = 0; k < plan.size(); ++k) {
    record(plan[k]);
    if (!ends[k]) continue;
    timer_->mark(cmd_);
    segments_.push_back(plan[k].group);
  }
}

void GpuSolver::read_times(FrameStats& s, int steps, double wall_ms) const {
  s.iterations = d_.solver.iterations;
  if (d_.solver.target_compression > 0)
    s.iterations += double(static_cast<const FrameResult*>(result_.mapped())->iterations) / steps;
  if (!timer_->available()) {
    s.step_ms = wall_ms / steps;
    return;
  }
  const std::vector<double> t = timer_->read_ms();
  for (size_t k = 0; k < segments_.size(); ++k) {
    const double ms = t[k + 1] - t[k];
    const PassGroup group = segments_[k];
    if (in_step(group)) s.step_ms += ms / steps;
    if (in_step(group) && profiling_) s.pass_ms[size_t(group)] += ms / steps;
    if (group == PassGroup::WhiteWater) s.white_water_ms += ms;
  }
}

// One frame: the plan's passes (sim/frame_plan.hpp) in one command buffer.
FrameStats GpuSolver::advance(int steps) {
  const auto start = std::chrono::steady_clock::now();
  begin();
  // The flow's clock stands still with the solids' (the settle): no water enters or leaves.
  const FlowCount flow = steps > 0 && !solids_held_ ? apply_flow() : FlowCount{};
  if (!solids_held_) flow_steps_ += steps;
  smoothed_current_ = false;  // the steps' sorts reuse the spare slot
  const WatchWords watch_reset;
  cmd_.update(watch_buf_, &watch_reset, sizeof watch_reset);
  cmd_.fill(work_, 0);  // the frame's work, from none
  if (!d_.bodies.empty()) cmd_.fill(body_push_, 0);  // and the bodies' pushes (none while held)
  step_in_frame_ = 0;
  if (d_.solver.target_compression > 0) {
    const uint32_t zero[4] = {0, 0, 0, 0};  // the frame's count of adaptive iterations
    cmd_.update(indirect_, zero, sizeof zero);
  }
  frame_time_ = steps * d_.dt;
  record_timed(frame_plan(d_, steps, outputs_));
  ++frames_advanced_;
  finish();
  FrameStats s = read_measures();
  s.solid_work += bodies_.take_work();
  if (steps > 0) read_times(s, steps, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  s.count_flow(flow, n_);
  return s;
}

// The frame's drains and emitters (sim/flow.hpp) at its start: the drains' passes on the GPU,
// submitted and read back (the counts, and the drained particles for the energy they took);
// then the layers due, made by the reference's function and written in the frame's commands
// past the count.
FlowCount GpuSolver::apply_flow() {
  const double t = double(flow_steps_) * d_.dt;
  if (!d_.flows() || !flow_due(d_.emitters, d_.drains, t, d_.spacing)) return {};
  FlowCount flow = d_.drains.empty() ? FlowCount{} : drain();
  // Stand-ins hold the places of the particles there: only what the emitters add goes up.
  const uint32_t from = n_;
  std::vector<glm::dvec3> x(n_), v(n_);
  std::vector<uint32_t> id(n_);
  const FlowCount emitted = pbflow::apply_flow(d_.emitters, {}, d_.flow_frame(capacity_), t, {x, v, id, {}, {}}, next_id_);
  flow.emitted = emitted.emitted, flow.energy += emitted.energy, flow.paused = emitted.paused;
  if (emitted.emitted == 0) return flow;
  n_ = sim_.count = uint32_t(x.size());
  auto pack = [&](const std::vector<glm::dvec3>& a) {
    std::vector<glm::vec4> out;
    for (size_t k = from; k < a.size(); ++k) out.emplace_back(glm::vec3(a[k]), 0.0f);
    return out;
  };
  const uint32_t count = n_ - from, at_vec4 = from * uint32_t(sizeof(glm::vec4));
  cmd_.update(at(X), pack(x).data(), count * uint32_t(sizeof(glm::vec4)), at_vec4);
  cmd_.update(at(V), pack(v).data(), count * uint32_t(sizeof(glm::vec4)), at_vec4);
  cmd_.update(id_[id_current_], id.data() + from, count * uint32_t(sizeof(uint32_t)), from * uint32_t(sizeof(uint32_t)));
  density_current_ = lists_built_ = smoothed_current_ = false;
  return flow;
}

FlowCount GpuSolver::drain() {
  cmd_.fill(drain_keep_.data(), 0);  // past the count too: the scan's total
  bind_particle_pass(drain_mark_);
  cmd_.bind("x", at(X));
  cmd_.bind("drains", drains_);
  cmd_.bind("keep", drain_keep_.data());
  cmd_.dispatch(n_);
  drain_keep_.run(cmd_);
  bind_particle_pass(drain_compact_);
  cmd_.bind("slots", drain_keep_.data());
  cmd_.bind("x_in", at(X));
  cmd_.bind("v_in", at(V));
  cmd_.bind("id_in", id_[id_current_]);
  cmd_.bind("x_out", at(Spare0));
  cmd_.bind("v_out", at(Spare1));
  cmd_.bind("id_out", id_[1 - id_current_]);
  cmd_.bind("drained", drained_);
  cmd_.bind("counts", drain_counts_);
  cmd_.dispatch(n_ + 1);
  finish();
  const std::vector<uint32_t> counts = drain_counts_.download<uint32_t>(2);
  FlowCount flow;
  if (counts[1] > 0) {
    const FlowFrame f = d_.flow_frame(capacity_);
    const std::vector<glm::vec4> out = drained_.download<glm::vec4>(2 * size_t(counts[1]));
    for (size_t k = 0; k < out.size(); k += 2) flow.energy -= f.energy(glm::dvec3(glm::vec3(out[k])), glm::dvec3(glm::vec3(out[k + 1])));
    flow.drained = counts[1];
    swap_roles(X, Spare0);
    swap_roles(V, Spare1);
    id_current_ = 1 - id_current_;
    n_ = sim_.count = counts[0];
    density_current_ = lists_built_ = smoothed_current_ = false;
  }
  begin();
  return flow;
}

}  // namespace pbflow
