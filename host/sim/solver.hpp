#pragma once
// What the run loop, the tests and the benchmarks see of a solver, GPU or reference.
#include <glm/glm.hpp>

#include "shaders/white_water.h"
#include "sim/flow.hpp"
#include "sim/solids/bodies.hpp"
#include "sim/solids/motion.hpp"
#include "sim/solids/obstacles.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <string>
#include <tuple>
#include <vector>

namespace pbflow {

// The passes of a frame, grouped as the benchmarks report them: a step's groups first
// (kStepGroups, timed per step), then the frame's end (the measures and each output).
enum class PassGroup { Grid, Lists, Density, Correction, Predict, Constraints, Coarse, Velocity, Viscosity,
                       Measures, Surface, WhiteWater };
constexpr size_t kStepGroups = size_t(PassGroup::Viscosity) + 1;
constexpr const char* kPassGroupNames[kStepGroups] = {"grid", "lists", "density",  "correction", "predict",
                                                      "constraints", "coarse", "velocity", "viscosity"};
constexpr bool in_step(PassGroup g) { return size_t(g) < kStepGroups; }

// What a frame produces besides the particles and the measures, as a capture, a live view or an
// export asks for it (capture::frame_outputs); each costs nothing while off.
struct FrameOutputs {
  bool surface = false;      // smoothed positions and drawn shapes, for drawing the fluid's surface
  bool white_water = false;  // white water moved and born (scene key white_water.*, where enabled)
  bool operator==(const FrameOutputs&) const = default;
};

// What the divergence watch saw in a frame's steps: particles whose position or velocity
// is not finite, faster than the scene's bound (Derived::speed_limit), or outside the
// domain. Counts are those of the first failing step.
struct Divergence {
  int first_step = -1;  // step within the frame of the first failure; -1: none
  uint32_t not_finite = 0, too_fast = 0, outside = 0;
  bool any() const { return first_step >= 0; }
  std::string describe(double speed_limit) const;  // "3 particles with ... ; 12 faster than ..."
};

// docs/design.md's measures, taken at the end of the last step from a fresh density pass.
struct FrameStats {
  double mean_compression = 0, max_compression = 0, kinetic_energy = 0, max_speed = 0;
  // sum m |g| (height above the domain's lowest corner along g), J: with kinetic_energy the
  // mechanical energy that must never rise (docs/design.md).
  double potential_energy = 0;
  // J the moving solids did on the fluid over the frame's steps (their pushes and their
  // images' pressure and drag, sim/solids/mirrors.hpp): what may be added to the energy. 0 without.
  double solid_work = 0;
  // The rigid bodies' kinetic and potential energy (heights as potential_energy's), J: the fluid's
  // partner in the energy bars; the work bodies and fluid do on each other is theirs, not solid_work.
  double body_energy = 0;
  double step_ms = 0;  // mean time of one step (GPU timestamps, else wall time); 0 when no step ran
  double iterations = 0;  // constraint iterations per step, on average (adaptive runs vary)
  double white_water_ms = 0;  // GPU time of the frame's white water passes (GpuSolver; 0 while off)
  // The particles after the frame, those its emitters added and its drains removed at its start,
  // and the energy they carried (J, kinetic and potential, in less out: sim/flow.hpp). `paused`:
  // an emitter waited for room under the capacity.
  uint32_t count = 0, emitted = 0, drained = 0;
  double flow_energy = 0;
  bool paused = false;
  // Mean GPU time per step of each pass group; filled only while profiling (GpuSolver).
  std::array<double, kStepGroups> pass_ms{};
  Divergence divergence;
  void count_flow(const FlowCount& f, size_t particles) {
    count = uint32_t(particles), emitted = f.emitted, drained = f.drained, flow_energy = f.energy, paused = f.paused;
  }
};

// docs/design.md's energy gain of a run: the largest (E_k - E_0) / PE_0 over its frames, with
// E = kinetic + potential energy less the work moving solids did since frame 0 (the first
// added, giving E_0 and PE_0). A
// sound run stays at or below 0.01. Also the largest rise of E over its running minimum
// (energy stored in compression and given back), in the same unit.
class EnergyGain {
 public:
  void add(const FrameStats& s) {
    work_ += s.solid_work + s.flow_energy;  // what the solids and the flow brought in is no gain of the solver's
    const double energy = s.kinetic_energy + s.potential_energy + s.body_energy - work_;
    if (!started_) std::tie(started_, e0_, pe0_, lowest_) = std::tuple(true, energy, s.potential_energy, energy);
    lowest_ = std::min(lowest_, energy);
    if (pe0_ > 0) {
      last_ = (energy - e0_) / pe0_;
      largest_rise_ = std::max(largest_rise_, (energy - lowest_) / pe0_);
    }
    largest_ = std::max(largest_, last_);
  }
  double largest() const { return largest_; }
  double last() const { return last_; }  // the latest frame's change
  double largest_rise() const { return largest_rise_; }

 private:
  bool started_ = false;
  double e0_ = 0, pe0_ = 0, largest_ = 0, last_ = 0, lowest_ = 0, largest_rise_ = 0, work_ = 0;
};

// Host copy of the per-particle state in ascending id order (the start's particles are ids 0 to
// n - 1, in the order of initial_particles; an emitter's get the next ones). id empty: 0 to n - 1.
struct ParticleState {
  std::vector<glm::dvec3> x, v, x_pred, curl;
  std::vector<double> rho, lambda;
  std::vector<uint32_t> id;
};

// A white water particle (shaders/white_water.h): its kind is the tag's low bits.
struct WhiteParticle {
  glm::dvec3 x, v;
  double life;    // s left
  uint32_t tag;   // kind, then emitter id and birth number
  uint32_t kind() const { return tag & ((1u << WHITE_KIND_BITS) - 1u); }
  // As the GPU's lists and the frame hold it: (x, life) and (v, the tag's bits).
  std::array<glm::vec4, 2> packed() const {
    return {glm::vec4(glm::vec3(x), float(life)), glm::vec4(glm::vec3(v), std::bit_cast<float>(tag))};
  }
  static WhiteParticle unpacked(const glm::vec4& x_life, const glm::vec4& v_tag) {
    return {glm::dvec3(x_life), glm::dvec3(v_tag), x_life.w, std::bit_cast<uint32_t>(v_tag.w)};
  }
};

// What capture and export read after a frame, in float: positions (xyz, w unused),
// velocities (xyz, w unused), densities, particle ids and, where the solver was asked for
// them (FrameOutputs::surface), the smoothed positions the fluid's surface is drawn
// from (xyz, w unused) and each one's drawn shape (two vec4s a particle, shaders/contract.h),
// both empty otherwise, in the solver's own order (id[k] is the id of entry k); and the white
// water alive, where asked for (FrameOutputs::white_water): (x, life) and (v, tag's bits). On the
// GPU they lie back to back in one buffer (frame_bytes), white water last: a count, then room for
// the capacity's positions and velocities; ids are read only for export.
// The entries of `ids` (a solver's order) in ascending id order: how download() and the exports
// lay particles out whatever the ids (emitters and drains leave gaps).
inline std::vector<size_t> ascending_ids(const std::vector<uint32_t>& ids) {
  std::vector<size_t> order(ids.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return ids[a] < ids[b]; });
  return order;
}

struct ParticleFrame {
  std::vector<glm::vec4> x, v;
  std::vector<float> rho;
  std::vector<uint32_t> id;
  std::vector<glm::vec4> x_smooth;
  std::vector<glm::vec4> shape;
  std::vector<glm::vec4> white_x, white_v;
};
// The frame's particles and white water in the world (positions, velocities), from the tank's
// frame the solvers work in: what the exports hold. A tank that never moved leaves them as they are.
inline void to_world(ParticleFrame& f, const TankMotion& tank, double dt) {
  if (tank.upright()) return;
  auto place = [&](std::vector<glm::vec4>& x, std::vector<glm::vec4>& v) {
    for (size_t i = 0; i < x.size() && i < v.size(); ++i) {
      const glm::dvec3 p(x[i]), u(v[i]);
      x[i] = glm::vec4(glm::vec3(tank.pose().world(p)), x[i].w);
      v[i] = glm::vec4(glm::vec3(tank.world_velocity(p, u, dt)), v[i].w);
    }
  };
  place(f.x, f.v);
  place(f.white_x, f.white_v);
}
// Where each array of the frame buffer starts, in bytes, for n particles and room for `white`
// white water particles (render_common.glsl reads the same layout in floats).
struct FrameOffsets {
  size_t x, v, rho, x_smooth, shape, white_count, white_x, white_v, end;
};
inline FrameOffsets frame_offsets(size_t n, size_t white = 0) {
  const size_t vec4s = n * sizeof(glm::vec4), floats = n * sizeof(float), white_vec4s = white * sizeof(glm::vec4);
  const size_t white_count = 5 * vec4s + floats, white_x = white_count + WHITE_HEADER_BYTES;
  return {0, vec4s, 2 * vec4s, 2 * vec4s + floats, 3 * vec4s + floats, white_count, white_x, white_x + white_vec4s,
          white_x + 2 * white_vec4s};
}
inline size_t frame_bytes(size_t n, size_t white = 0) { return frame_offsets(n, white).end; }
// The white water's header (WHITE_HEADER_BYTES at white_count) is a draw command for the living
// (GL's DrawArraysIndirectCommand: count, instances, first, base instance), so that the renderer
// draws them and not the whole room, which at a million particles cost a 1080p frame 0.8 ms of
// an H200's time.
inline std::array<uint32_t, 4> white_header(size_t alive) { return {uint32_t(alive), 1, 0, 0}; }
// White water into a frame's two arrays, packed (WhiteParticle::packed).
inline void add_white_water(ParticleFrame& f, const std::vector<WhiteParticle>& white) {
  for (const WhiteParticle& p : white) {
    const auto [x_life, v_tag] = p.packed();
    f.white_x.push_back(x_life);
    f.white_v.push_back(v_tag);
  }
}

// A drawn shape's two vec4s, as shaders/shape_layout.glsl lays them out: the ellipsoid's
// matrix T, in particle radii (the identity draws the sphere), and its longest semi-axis.
inline std::array<glm::vec4, 2> encode_shape(const glm::dmat3& t, double longest_axis) {
  return {glm::vec4(t[0][0] - 1, t[1][1] - 1, t[2][2] - 1, longest_axis - 1), glm::vec4(t[1][0], t[2][0], t[2][1], 0)};
}
inline glm::dmat3 decode_shape(const glm::vec4& a, const glm::vec4& b) {
  return glm::dmat3(a.x + 1, b.x, b.y, b.x, a.y + 1, b.z, b.y, b.z, a.z + 1);
}

// Where the solids stand, how they move, their clock and the emitters': what a live run carries
// from a solver to the one made anew in its place (another setting, a restart). The clocks are
// times, s: a solver of another step counts them in its own steps (Solver::carry_clocks).
struct SolidsState {
  double time = 0;  // the solids' (their steps moved times dt)
  std::vector<Obstacle> obstacles;  // as the solver holds them (Derived::obstacles)
  TankMotion tank;
  double flow_time = 0;  // the emitters' (steps run but held)
  std::vector<Body> bodies;  // their velocities (their poses are their obstacles')
};

class Solver {
 public:
  virtual ~Solver() = default;
  // Runs `steps` time steps (0: none), then measures at the final positions.
  virtual FrameStats advance(int steps) = 0;
  virtual ParticleFrame read_frame() const = 0;  // the state after the last advance()
  virtual ParticleState download() const = 0;     // everything, in id order
  virtual void upload(const ParticleState& s) = 0;  // x, v, x_pred and rho, in id order
  virtual size_t particle_count() const = 0;
  // The most particles it holds at once (Derived::capacity_for): its buffers' and a frame's room.
  size_t capacity() const { return capacity_; }
  virtual std::string device_name() const = 0;
  // One relaxation of the start: x* = x, the grid and lists at x*, a single constraint
  // iteration (smoothed as the scene smooths) with the coarse correction beside it, x = x*. No
  // time passes: no gravity, no LDC, no XSPH, and the velocities are zero after. One iteration
  // whatever the step runs: every schedule relaxes towards the same rest (docs/physics.md,
  // "The start").
  virtual void relax() = 0;

  // From the next advance() on, each frame also produces `outputs` (frame_plan), and no more:
  // off, an output costs no pass and holds no buffer. White water is on only where the scene
  // enables it, and starts with none alive; it writes nothing of the fluid's, so a run's stats
  // are the same with it or without.
  virtual void set_outputs(FrameOutputs outputs) = 0;
  FrameOutputs outputs() const { return outputs_; }
  // The most white water alive at once: the frame buffer's room for it (frame_bytes), the
  // scene's cap where it has white water at all (0 where white_water.enabled is false), on or
  // off; none is alive while off.
  virtual size_t white_water_capacity() const = 0;
  virtual std::vector<WhiteParticle> white_water() const = 0;  // those alive, in no set order
  virtual void upload_white_water(const std::vector<WhiteParticle>& w) = 0;  // at most the capacity

  // Where each obstacle stands after the last advance() (scene order): for drawing them.
  virtual std::vector<Pose> obstacle_poses() const = 0;
  // The rigid bodies as the last advance() left them (their obstacles' poses: obstacle_poses()).
  virtual std::vector<Body> bodies() const = 0;
  // The tank's motion: where it stands in the world after the last advance() (the solver works in
  // its frame) and where it stood a step before.
  virtual const TankMotion& tank() const = 0;
  Pose tank_pose() const { return tank().pose(); }
  // While held, moving solids stand where they are and their clock stands still (the settle
  // brings the fluid to rest around them at time 0).
  void hold_solids(bool held) { solids_held_ = held; }
  // A viewer's hand, where the solver was made steerable (Derived::steerable, pbflow serve):
  // obstacle k shifted from where the scene places it, reached at the speed a step keeps sound
  // (Derived::drag); the tank's motion from the last step's end, starting where it is; the tank
  // turned to `to` about its floor's centre (Derived::tilt).
  virtual void drag(size_t k, const glm::dvec3& shift) = 0;
  virtual void release(size_t k) = 0;  // a body the hand held let go (Derived::release)
  virtual void shake(const Motion& m) = 0;
  virtual void tilt(const glm::dquat& to) = 0;
  // The emitters on or off from the next frame (a viewer's tap); off, every layer due is skipped.
  virtual void set_emitting(bool on) = 0;
  virtual SolidsState solids() const = 0;
  // The solids (of this scene) placed as `s` has them, their clock and motions carried on.
  virtual void carry(const SolidsState& s) = 0;

 protected:
  FrameOutputs outputs_;
  bool solids_held_ = false;
  size_t capacity_ = 0;
  long flow_steps_ = 0;   // steps run, the emitters' clock
  long steps_moved_ = 0;  // steps whose solids have moved: their time is this times dt
  // The solids as a solver holds them, with both clocks in s (solids()).
  SolidsState solids_state(const std::vector<Obstacle>& obstacles, const TankMotion& tank, const std::vector<Body>& bodies,
                           double dt) const {
    return {double(steps_moved_) * dt, obstacles, tank, double(flow_steps_) * dt, bodies};
  }
  // The clocks of `s` in steps of dt: the nearest step, a half step's motion at most.
  void carry_clocks(const SolidsState& s, double dt) {
    steps_moved_ = std::lround(s.time / dt);
    flow_steps_ = std::lround(s.flow_time / dt);
  }
  uint32_t next_id_ = 0;  // the id an emitter's next particle gets
};

}  // namespace pbflow
