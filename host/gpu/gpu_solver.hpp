#pragma once
// The solver on Vulkan compute: every pass of docs/design.md's step is one shader, and a
// whole frame (all its steps and the measures) is one command buffer; where the scene has bodies,
// one up to each pass that pushes them (gpu_bodies.cpp).
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string_view>
#include <span>
#include <vector>

#include "gpu/buffer_plan.hpp"
#include "gpu/key_constants.hpp"
#include "gpu/gpu_grid.hpp"
#include "gpu/gpu_scan.hpp"
#include "sim/solids/coupling.hpp"
#include "sim/solids/obstacles.hpp"
#include "sim/params.hpp"
#include "sim/solver.hpp"
#include "sim/frame_plan.hpp"
#include "vk/buffer.hpp"
#include "vk/commands.hpp"
#include "vk/context.hpp"
#include "vk/program.hpp"
#include "vk/timer.hpp"

namespace pbflow {

// How the passes are laid out where what is fastest depends on the device: the device's choice
// (for_device), or another, for the tests to hold each to the reference on any device.
struct GpuLayout {
  // The lists pass lists the images of the particles near obstacles in its walk, one dispatch
  // (a GPU), rather than in a near variant dispatched after it (a CPU device: it runs every branch
  // for all lanes, masked). Measured both ways on an H200 and lavapipe: docs/performance.md.
  bool near_in_walk = false;
  static GpuLayout for_device(const vk::DeviceInfo& device) { return {device.kind != "cpu"}; }
};

class GpuSolver : public Solver {
 public:
  GpuSolver(const vk::Context& ctx, const Derived& d, const std::vector<glm::dvec3>& x0,
            std::optional<GpuLayout> layout = std::nullopt);

  FrameStats advance(int steps) override;
  ParticleFrame read_frame() const override;
  // Copies x, v, rho and the smoothed positions and shapes where asked for (frame_bytes layout) into
  // `dst` on the device: no host round trip.
  void copy_frame(const vk::Buffer& dst) const;
  void set_outputs(FrameOutputs outputs) override;  // builds an output's programs when first asked
  size_t white_water_capacity() const override { return d_.white_capacity(); }
  std::vector<WhiteParticle> white_water() const override;
  void upload_white_water(const std::vector<WhiteParticle>& w) override;
  size_t particle_count() const override { return n_; }
  void relax() override;
  std::vector<Pose> obstacle_poses() const override { return d_.obstacle_poses(); }
  std::vector<Body> bodies() const override { return d_.bodies; }
  const TankMotion& tank() const override { return d_.tank; }
  void drag(size_t k, const glm::dvec3& shift) override { d_.drag(k, shift); }
  void release(size_t k) override { d_.release(k); }
  void shake(const Motion& m) override { d_.shake(m, double(steps_moved_) * d_.dt); }
  void tilt(const glm::dquat& to) override { d_.tilt(to, double(steps_moved_) * d_.dt); }
  void set_emitting(bool on) override { d_.emitting = on; }
  SolidsState solids() const override { return solids_state(d_.obstacles, d_.tank, d_.bodies, d_.dt); }
  void carry(const SolidsState& s) override;
  std::string device_name() const override;

  // Pass-level access for the tests: begin(), record passes, finish() submits and waits.
  void begin() { cmd_.begin(); }
  void finish() { cmd_.submit_and_wait(); }
  // A grid build and the neighbour lists at the sorted positions (neighbour_lists.comp).
  void grid_at_positions();    // sorts x, v, id by the cells of x
  void grid_at_predictions();  // sorts x, x_pred, id by the cells of x_pred
  void density();
  void correction_and_predict();  // LDC's v += f dt, then predict()'s work in the same pass
  void predict();
  // With `indirect`, group counts come from that buffer (adaptive iterations).
  void constraint_lambda(const vk::Buffer* indirect = nullptr);
  void constraint_smooth(const vk::Buffer* indirect = nullptr);  // solver.lambda_smoothing passes over lambda
  void constraint_apply(double relaxation, const vk::Buffer* indirect = nullptr);
  void coarse_correction();  // x_lambda's x_pred += the coarse grid's correction, from a lambda pass's rho
  void velocity_update();
  void viscosity_vorticity();
  void vorticity_force();
  void move_solids();  // Pass::Move: the solids to the step's end (Derived::move_solids)
  void update_obstacle_header();  // the solids' poses now into the obstacles' header, in the commands
  FlowCount apply_flow();  // the frame's drains and emitters, before its steps (sim/flow.hpp)
  FlowCount drain();       // the drains' passes, submitted and read back: what they took
  void watch();  // flags non-finite, runaway and escaped particles of this step
  // The fluid surface's positions at x, from the last lists (smoothed_positions.comp), into a
  // spare slot, which no pass writes again before the next frame's first grid build, and
  // the particles' drawn shapes.
  void smoothed_positions();
  // A frame's white water (shaders/white_water.h), `elapsed` s: the living moved into the other
  // list and the survivors packed back in order (white_water_advect, white_water_compact.comp),
  // then the fluid's births counted from the last lists and appended in the particles' order
  // (white_water_emit, white_water_birth.comp); `frame` picks their random numbers.
  void white_water_advect(double elapsed);
  void white_water_emit(double elapsed, uint32_t frame);
  // One pass of a plan (sim/frame_plan.hpp); `indirect`: the constraint passes' dispatch, where
  // an adaptive pair is gated.
  void record(const PlannedPass& pass, const vk::Buffer* indirect = nullptr);
  void record_measures();  // the reductions of rho at x, and the frame's counts beside them

  // Timestamps after every pass group, reported in FrameStats::pass_ms (benchmarks).
  void set_profiling(bool on) { profiling_ = on; }

  void upload(const ParticleState& s) override;
  ParticleState download() const override;

 private:
  enum Slot { X, V, XPred, Spare0, Spare1, kSlots };  // roles of the vec4 arrays, swapped on the host
  static_assert(kSlots == SolverBuffers::kParticleVec4s);
  const vk::Buffer& at(Slot s) const { return vec4_[role_[s]]; }
  void swap_roles(Slot a, Slot b) { std::swap(role_[a], role_[b]); }
  // Sorts `keyed`, `carried` and the ids by the cells of `keyed`, then lists its neighbours.
  void sort_by_cells(Slot keyed, Slot carried);
  // A neighbour pass's variants (shaders/neighbours.glsl), each over its own particles: the list
  // readers, blind to the obstacles' mirrors; where the scene has obstacles, the near readers,
  // over the particles the lists pass found within h of one; the cell walkers, over overflowed
  // lists (over every particle without lists).
  struct NeighbourPass {
    vk::Program lists, near, cells;
  };
  // A particle pass's program: SimConstants pushed, the solver's keys offered, `constants` its own.
  vk::Program particle_program(std::string_view shader, std::span<const vk::Constant> constants = {},
                               uint32_t workgroup_size = 0) const;
  // `constants`: the shader's own; neighbour_pass adds those of shaders/neighbours.glsl.
  NeighbourPass neighbour_pass(std::string_view shader, std::vector<vk::Constant> constants) const;
  // Runs `pass` with the grid, its lists and the bindings `bind` makes: the list readers
  // over every particle, the near readers over those near obstacles, and the cell walkers
  // over those whose lists overflowed (an empty dispatch, mostly), with no barrier between.
  void run_neighbour_pass(const NeighbourPass& pass, const vk::Buffer* indirect, const std::function<void()>& bind);
  void bind_particle_pass(const vk::Program& p);
  void bind_neighbours();
  vk::Program lists_program(bool near) const;  // the lists pass's walk or its near variant
  // Whether the neighbour passes have near readers (the scene has obstacles and lists), the lists
  // walk lists the near particles' images itself (GpuLayout), and the lists pass has a near variant.
  bool near_readers() const;
  bool walk_lists_near() const;
  bool near_variant() const;
  void neighbour_lists(const vk::Buffer& x);
  void density_at_positions();  // rho at x for the LDC force and the measures, from the last step's lists
  FrameStats read_measures() const;
  // Records `plan`, a timer mark closing each segment of one group: every group while
  // profiling, else the steps as one and each group of the frame's end.
  void record_timed(const std::vector<PlannedPass>& plan);
  // The stats' times from the segments' marks: a step's mean, its groups' while profiling, white water's.
  void read_times(FrameStats& s, int steps, double wall_ms) const;
  void run_particle_pass(const vk::Buffer* indirect);
  void reduce_measures(const vk::Buffer& into);  // (mean c, max c, kinetic energy, max speed) of rho_, v
  void adaptive_iterations();                    // iteration pairs until the target (check_converged)
  void build_coarse();
  void build_drains();
  void build_bodies();
  // The bodies' push sums where the scene has bodies; else a stand-in the shaders never write (BODIES).
  const vk::Buffer& body_pushes() const { return d_.bodies.empty() ? work_ : body_push_; }
  // The bodies (gpu_bodies.cpp): each body's water line from x_pred (body_water_line.comp), before
  // the coarse correction moves it; after a pass that pushed them, the sums read back and their
  // answer (BodyCoupling: the give-way, the coarse correction's buoyancy, the dashpot's kick)
  // between two submits, their poses into the next.
  void body_water_line();
  void answer_bodies(Pass pass);
  void read_body_pushes();
  std::vector<double> body_water_lines() const;

  const vk::Context& ctx_;
  Derived d_;
  SimConstants sim_;
  KeyConstants keys_;  // offered to every particle pass
  uint32_t n_;  // particles now (at most capacity_)
  GpuLayout layout_;
  SolverBuffers plan_;  // every buffer below, in bytes
  bool viscosity_pass_, vorticity_pass_, correction_pass_;
  bool density_current_ = false;  // rho already matches x (the viscosity pass or a density pass left it)
  bool lists_built_ = false;      // the grid and lists follow the particles' order (built since the upload)
  bool smoothed_current_ = false; // the spare slot holds the smoothed positions (since the last one recorded)

  // The lists pass's walk and, where the scene has obstacles and the walk does not list their
  // images (or there are no lists, for a mesh's creases), its near variant (neighbour_lists.comp).
  vk::Program lists_, near_lists_, predict_, velocity_;
  NeighbourPass density_, correction_, lambda_, smooth_, apply_, viscosity_, vorticity_, positions_;
  vk::Program reduce_, reduce_final_, check_converged_, watch_;
  // Built where the scene runs the coarse correction: the sweeps as one program in one
  // workgroup of coarse_sweep_threads_, or (0) a program per colour, a dispatch each.
  vk::Program coarse_deposit_, coarse_prepare_, coarse_gradient_, coarse_apply_;
  std::vector<vk::Program> coarse_sweeps_;
  uint32_t coarse_sweep_threads_ = 0;
  GpuGrid grid_;
  std::array<vk::Buffer, SolverBuffers::kParticleVec4s> vec4_;
  std::array<int, kSlots> role_{X, V, XPred, Spare0, Spare1};
  std::array<vk::Buffer, SolverBuffers::kIdArrays> id_;
  int id_current_ = 0;
  vk::Buffer rho_, neighbour_count_, neighbour_list_;
  vk::Buffer x_lambda_, x_lambda_spare_;  // (x_pred, lambda) and its smoothing spare (constraint_lambda.comp)
  vk::Buffer curl_, partials_, result_, obstacles_;
  vk::Buffer work_;  // solids.glsl's work: per slot, summed by reduce_stats
  vk::Buffer crease_records_;  // each particle's creases, from the lists pass (solids.glsl)
  // The particles' distances from the obstacles (SolverBuffers::distances): [distances_current_]
  // at x_pred's positions; an Apply writes the other and swaps them as it swaps x_pred's role.
  std::array<vk::Buffer, 2> distances_;
  int distances_current_ = 0;
  vk::Buffer shape_;  // the drawn shapes, two vec4s a particle, where smoothed positions are asked for
  vk::Buffer check_, indirect_;
  // The cell walkers' dispatch and the near readers' (neighbour_lists.comp), and their copy for an
  // adaptive iteration pair: zero where the pair does not run (check_converged.comp).
  vk::Buffer overflow_groups_, overflow_gated_;
  vk::Buffer coarse_sums_, coarse_phi_, coarse_grad_, coarse_open_;
  // The drains' passes and buffers (SolverBuffers::drains), where the scene has drains.
  vk::Program drain_mark_, drain_compact_;
  vk::Buffer drains_, drained_, drain_counts_;
  GpuScan drain_keep_;
  // The bodies' program and push sums (SolverBuffers::body_push), where the scene has bodies.
  vk::Program body_line_;
  vk::Buffer body_push_, body_read_, body_grad_read_;  // the sums, their host copy, the coarse gradient's
  BodyCoupling bodies_;
  vk::Buffer watch_buf_;  // watch.comp: flags, first step, counts, the step being watched
  uint32_t step_in_frame_ = 0;  // adaptive iterations: the last check's measures, dispatch arguments + count
  // White water, where asked for: its count (the living, and the living and born while the
  // births are placed), its lists ([0] the living, [1] where they move before the survivors are
  // packed back into [0]), each (x, life) and (v, tag); the prefix sums that fix their order.
  uint32_t frames_advanced_ = 0;
  double frame_time_ = 0;  // s the frame's steps advance, for white water
  NeighbourPass white_emit_;
  vk::Program white_advect_, white_compact_, white_birth_;
  vk::Buffer white_count_;
  std::array<vk::Buffer, 2> white_x_, white_v_;
  GpuScan white_survivors_, white_births_;
  vk::CommandList cmd_;
  std::unique_ptr<vk::GpuTimer> timer_;
  bool profiling_ = false;
  std::vector<PassGroup> segments_;  // the group timed between marks k and k+1
};

}  // namespace pbflow
