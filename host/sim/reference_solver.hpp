#pragma once
// The C++ reference: the same passes in the same order as the GPU solver, in double
// precision and written for clarity. Tests compare every GPU pass with it; it is also
// the CPU baseline (--device cpu).
#include <algorithm>
#include <array>
#include <memory>
#include <vector>

#include "sim/solids/coupling.hpp"
#include "sim/solids/mirrors.hpp"
#include "sim/params.hpp"
#include "sim/solver.hpp"
#include "sim/frame_plan.hpp"

namespace pbflow {

class ReferenceSolver : public Solver {
 public:
  ReferenceSolver(const Derived& d, const std::vector<glm::dvec3>& x0);

  FrameStats advance(int steps) override;
  ParticleFrame read_frame() const override;
  ParticleState download() const override { return state; }
  void upload(const ParticleState& s) override;
  size_t particle_count() const override { return state.x.size(); }
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
  std::string device_name() const override { return "cpu (C++ reference)"; }
  void set_outputs(FrameOutputs outputs) override;
  size_t white_water_capacity() const override;
  std::vector<WhiteParticle> white_water() const override { return white; }
  void upload_white_water(const std::vector<WhiteParticle>& w) override;

  void run(const PlannedPass& pass);  // one pass of a plan (sim/frame_plan.hpp)
  void adaptive_iterations();         // iteration groups until the target, as the GPU's
  FrameStats measure() const;  // the measures of rho at x (after a Density pass) and of v

  // The passes of one step (docs/design.md), public so that tests can run them one by one.
  void build_grid(const std::vector<glm::dvec3>& at);  // bins particles by cell
  void density();                                      // rho at x, from the lists of the last build (at x after build_grid)
  void correction();                                   // v += f_LDC dt
  void predict();                                      // v += g dt, x_pred
  void constraint_lambda();                            // lambda at x_pred
  void constraint_smooth();                            // lambda averaged over the neighbours, lambda_smoothing times
  void constraint_apply(double relaxation);                 // x_pred += relaxation * dp
  void coarse_correction();                            // x_pred += the coarse grid's correction, from a lambda pass's rho
  void velocity_update();                              // v from x_pred - x; x = x_pred
  void viscosity_vorticity();                          // XSPH, the curl
  void vorticity_force();                              // v += f_vort dt
  // The positions and shapes drawn for the fluid's surface (smoothed_positions.comp), from the
  // lists of the last build (at x after build_grid), as density(). A shape is the ellipsoid's
  // matrix in particle radii and its longest semi-axis (shaders/contract.h).
  struct DrawnParticles {
    std::vector<glm::dvec3> x;
    std::vector<glm::dmat3> shape;
    std::vector<double> longest_axis;
  };
  DrawnParticles smoothed_positions();
  // A frame's white water (shaders/white_water.h), `elapsed` s: the living moved, aged and
  // retyped from the fluid around them (white_water_advect.comp), then the fluid's births at x,
  // from the last lists (white_water_emit.comp); `frame` picks their random numbers.
  void white_water_advect(double elapsed);
  void white_water_emit(double elapsed, uint32_t frame);

  FlowCount apply_flow();  // the frame's drains and emitters, before its steps

  // The LDC acceleration on particle i (from rho and x); correction() applies it.
  // `work` (where given) gains the work per unit mass its moving solids' images did.
  glm::dvec3 correction_force(size_t i, double* work = nullptr) const;

  const Derived& derived() const { return d_; }
  ParticleState state;
  DrawnParticles drawn;  // the last frame's smoothed positions and shapes, where asked for
  std::vector<WhiteParticle> white;  // alive, where asked for

 private:
  // The step's neighbour sets, as the GPU's lists (shaders/neighbour_lists.comp): built
  // after a grid build, at x for density or at x_pred for constraint_lambda, from the 27
  // cells, keeping those within h and then their images within h; read by every pass of
  // the step, which places an image behind the walls near the particle's position then.
  struct Neighbour {
    uint32_t j;
    uint32_t image;  // the mirrors j is reflected across (sim/solids/mirrors.hpp; 0: j itself)
  };
  void build_neighbours(const std::vector<glm::dvec3>& at);
  void density_at_positions();  // rho at x, from the last step's lists (GpuSolver::density_at_positions)
  template <class F>
  void for_each_candidate(const glm::dvec3& xi, F&& visit) const;
  template <class F>
  void for_each_neighbour(size_t i, const glm::dvec3& xi, F&& visit) const;

  glm::ivec3 cell_of(const glm::dvec3& x) const;
  size_t cell_id(const glm::ivec3& c) const { return (size_t(c.z) * d_.grid.y + c.y) * d_.grid.x + c.x; }
  // Out of the obstacles, then into the walls; `work` gains what moving ones did (push_work).
  glm::dvec3 project_out_of_solids(glm::dvec3 x, double& work) const;
  // The move from -> to stopped at the first obstacle on its way, then out of solids
  // (solids.glsl's predicted_position).
  glm::dvec3 move_outside_solids(const glm::dvec3& from, glm::dvec3 to, double& work) const;

  double mean_compression() const;  // of state.rho

  // Rigid bodies (sim/solids/coupling.hpp, reference_bodies.cpp). push_body: body b's solid pushed
  // the particle at x by dx (velocity changes, the images' dashpot, alike: BodyCoupling::kick);
  // whether the solid is a body (b >= 0), whose pushes are no solid work.
  bool push_body(int b, const glm::dvec3& x, const glm::dvec3& dx) const;
  // After a pass that pushed bodies (`kick`: the dashpot's velocity changes): their answer.
  void answer_bodies(bool kick);
  // The coarse correction's share (BodyCoupling::add_buoyancy), each body's water line from x_pred.
  void add_buoyancy(const std::vector<glm::dvec3>& grad);
  std::vector<uint32_t> coarse_solve();  // phi into coarse_phi_; each node's flags (contract.h, COARSE_WORDS)
  // grad phi at the coarse nodes with fluid (`fluid`), from coarse_phi_.
  std::vector<glm::dvec3> coarse_gradient(const std::vector<uint32_t>& flags) const;
  void watch_step(int step, Divergence& watch) const;  // the divergence watch (shaders/watch.comp)

  Derived d_;
  uint32_t frames_advanced_ = 0;  // white water's random stream
  double solid_work_ = 0;         // J/kg moving solids did in the current advance()
  double frame_time_ = 0;         // s the frame's steps advance, for white water
  long iterations_run_ = 0;  // constraint iterations in the current advance()
  int step_in_frame_ = 0;    // the watch's step
  Divergence watch_;         // what the watch saw in the current advance()
  FrameStats measured_;      // the current advance()'s measures
  std::vector<double> coarse_phi_;  // the coarse correction's solution, the next step's start
  // The bodies' answer to the pushes (push_body, from passes that only read the solver).
  mutable BodyCoupling bodies_;
  std::vector<std::vector<size_t>> cells_;  // particles binned by cell at the last build_grid
  // Per particle, as the GPU's lists: neighbour_capacity entries within h when the list was
  // built, and their count (past the capacity: overflowed, walk the cells).
  std::vector<Neighbour> neighbour_list_;
  std::vector<uint32_t> neighbour_count_;
  std::vector<Creases> creases_;  // each particle's, found when the lists were built
  bool neighbours_current_ = false;              // built since the last build_grid
  bool neighbours_built_ = false;                // built since the particles were set (GpuSolver::lists_built_)
  // The solids moved since the lists were built (LDC's correction comes after Move): their
  // obstacle images are tested again (Mirrors::of).
  bool moved_since_lists_ = false;
};

// Visits j for every particle binned in the 27 cells around xi (distance not tested).
template <class F>
void ReferenceSolver::for_each_candidate(const glm::dvec3& xi, F&& visit) const {
  glm::ivec3 c = cell_of(xi);
  for (int z = std::max(c.z - 1, 0); z <= std::min(c.z + 1, d_.grid.z - 1); ++z)
    for (int y = std::max(c.y - 1, 0); y <= std::min(c.y + 1, d_.grid.y - 1); ++y)
      for (int x = std::max(c.x - 1, 0); x <= std::min(c.x + 1, d_.grid.x - 1); ++x)
        for (size_t j : cells_[cell_id({x, y, z})]) visit(j);
}

// As neighbours.glsl: i's list, or, where it holds more than the GPU's capacity, every
// particle in the cells around i's position now (xi) with all its images behind the
// mirrors near xi. visit(j, image): the image is placed from xi.
template <class F>
void ReferenceSolver::for_each_neighbour(size_t i, const glm::dvec3& xi, F&& visit) const {
  const uint32_t count = neighbour_count_.at(i);
  Mirrors mirrors = mirrors_near(d_, xi);
  mirrors.take(creases_.at(i));
  if (count > d_.neighbour_capacity) {
    for_each_candidate(xi, [&](size_t j) {
      for (int k = 0; k < kImages; ++k)
        if ((k & mirrors.axes) == k) visit(j, Image{&mirrors, k, false});
    });
  } else {
    const Neighbour* list = neighbour_list_.data() + i * d_.neighbour_capacity;
    for (uint32_t k = 0; k < count; ++k) visit(list[k].j, Image{&mirrors, int(list[k].image), !moved_since_lists_});
  }
}

}  // namespace pbflow
