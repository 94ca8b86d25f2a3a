#pragma once
// Solver parameters: what a scene sets (SolverParams; every key's default, range and reason
// are in the key table, scene/keys.cpp) and what the passes read (SimConstants, derived from them).
#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "shaders/sim_constants.h"
#include "sim/flow.hpp"
#include "sim/solids/bodies.hpp"
#include "sim/solids/obstacles.hpp"
#include "sim/white_water.hpp"

namespace pbflow {

enum class Method { Pbf, Ldc };
Method parse_method(const std::string& name);  // throws std::invalid_argument
const char* method_name(Method m);

struct SolverParams {
  Method method;
  int iterations;          // constraint iterations per step (the minimum when adaptive)
  int max_iterations;      // adaptive: at most this many per step
  double target_compression;  // adaptive when > 0: iterate until the mean compression is at most this
  int substeps;            // steps per frame: dt = 1 / (fps * substeps); kChosenSubsteps: the scene picks (chosen_substeps)
  double kernel_ratio;     // h / particle spacing
  double rest_density;     // rho0, kg/m^3
  double relaxation;       // eps as a fraction of an interior particle's sum |grad C|^2
  double jacobi_gain;      // (0, 1]: the most a step's passes correct any density mode, as a fraction of its error
  int lambda_smoothing;    // 0, 2 or 4: passes averaging lambda over the neighbours before each constraint_apply;
                           // kChosenSmoothing: derive() picks 2 or 4 (default_smoothing)
  double xsph;             // XSPH viscosity c (fraction of the neighbour-averaged relative velocity)
  double vorticity;        // vorticity confinement epsilon, m/s (0: off)
  double damping;          // pairwise dashpot on the relative normal velocity (viscosity_vorticity.comp)
  double ldc_strength;     // LDC's K as a fraction of the largest K the step carries (ldc_k_limit)
  double ldc_k;            // LDC strength K, 1/s^2, when a scene states it; < 0: from ldc_strength
  bool ldc_clamp;          // LDC reads densities below rho0 as rho0 (only compression pushes)

  static constexpr int kChosenSmoothing = -1, kChosenSubsteps = -1;
  // XSPH, vorticity and the damping share one neighbour pass (viscosity_vorticity).
  bool viscosity_pass() const { return xsph > 0 || vorticity > 0 || damping > 0; }
};

// A solver or white water key as a shader reads it, a specialisation constant
// (gpu/key_constants.hpp): its dotted name and the member its value lies in. derive() lists
// every such key from the key table (scene/keys.cpp), their one declaration.
using ParamTarget = std::variant<std::monostate, double SolverParams::*, int SolverParams::*, bool SolverParams::*,
                                 double WhiteWaterParams::*, int WhiteWaterParams::*, bool WhiteWaterParams::*>;
struct ParamKey {
  std::string_view name;
  ParamTarget target;
};

// The push-constant block every particle pass reads, generated from its one declaration in
// shaders/sim_constants.h (which says why the layouts agree).
#define PBFLOW_GLSL_TYPE_float float
#define PBFLOW_GLSL_TYPE_uint uint32_t
#define PBFLOW_GLSL_TYPE_vec3 glm::vec3
#define PBFLOW_GLSL_TYPE_ivec3 glm::ivec3
struct SimConstants {
#define SIM_FIELD(type, name) PBFLOW_GLSL_TYPE_##type name;
  SIM_CONSTANTS(SIM_FIELD)
#undef SIM_FIELD
};

// Everything a pass needs, in double for the reference solver; to_gpu() narrows it.
struct Derived {
  glm::dvec3 domain_min, domain_max, wall_min, wall_max, gravity;
  glm::ivec3 grid;
  double h, spacing, dt, mass, rho0, epsilon;
  // Kernel radii a particle falling through the whole domain moves in one step: past 1 it
  // passes neighbours it never saw, outside the lattice model that sizes the passes.
  double travel;
  // The largest gain of one unrelaxed Jacobi pass over all density modes (host/sim/stability.hpp),
  // as a lone pass runs it and as a pair's passes run it (lambda smoothed first, if the scene smooths).
  double jacobi_gain_max, paired_gain_max;
  // One constraint iteration: its under-relaxation, and whether lambda is smoothed before it.
  struct ConstraintPass {
    double relaxation;  // the Jacobi under-relaxation ω
    bool smoothed;
  };
  // A step's `passes` iterations. Pairs run smoothed at paired_gain_max's relaxation
  // (jacobi_schedule). A single iteration runs as a pair's first pass does, the coarse
  // correction beside it (without it, smoothed and that bold, the squeezed floor of a pbf@1
  // tank oscillated at 0.4-2.9 m/s, docs/physics.md); unsmoothed (lambda_smoothing 0), and
  // as an odd count's last pass, it runs at jacobi_gain_max's.
  std::vector<ConstraintPass> constraint_schedule(int passes) const;
  // Whether the constraint passes average lambda (solver.lambda_smoothing > 0): pairs, and a
  // single iteration with the coarse correction beside it.
  bool smooths_lambda() const { return solver.lambda_smoothing > 0; }
  // The most white water alive at once: its cap where the scene enables it, else 0.
  size_t white_capacity() const { return white_water.enabled ? size_t(white_water.max_particles) : 0; }
  // LDC: the K the force uses (1/s^2; 0 for pbf) and the K at which the explicit force
  // alone goes unstable at this dt and h / spacing (K dt^2 s = 4).
  double ldc_k, ldc_k_limit;
  // The explicit terms' caps in squeezed fluid, where their stiffness grows with the
  // neighbours inside h (stability.hpp): a particle's K is min(K, ldc_room K (rho0/rho)^2),
  // i.e. at most kLdcCap of the limit; a pair's dashpot is min(damping, damping_limit rho0/rho),
  // damping_limit keeping the fastest mode at rest at 1.5 (it is driven past 2).
  double ldc_room, damping_limit;
  // Entries per particle in the GPU's neighbour lists (shaders/neighbours.glsl): room for
  // the neighbours inside h at kNeighbourHeadroom times rho0; a particle with more walks
  // its cells instead.
  uint32_t neighbour_capacity;
  // The coarse correction of the long density modes, before a step's smoothed passes: the
  // compression deposited on nodes about COARSE_CELL spacings apart, cells sized per axis to
  // tile the walls' span (a cell straddling a wall held its column low), a Poisson problem
  // solved there, x_pred moved by `strength` times its solution's gradient (docs/physics.md
  // says why): COARSE_STRENGTH for pairs, COARSE_LONE_STRENGTH for a single iteration. strength 0:
  // not run (a single unsmoothed pass, which it drove to make energy).
  struct Coarse {
    glm::ivec3 nodes{0};
    glm::dvec3 cell{0.0};
    double strength = 0;
    // Each node's share of its reach outside every obstacle (1 without them; open_fraction).
    // The solve counts a node a solid fills (but for COARSE_FILL) as fluid at rest, as the mirrors
    // do: as air it drew the fluid in and a ball stirred the settled tank (0.87 J in 1 s without
    // the dashpot); as walls it left a void under the ball that never filled. A node beside a
    // solid is fluid where the water fills its open part: above the water line it is air.
    std::vector<float> open;
    // Which of each node's samples the solids left still by the last move lie in (mark_inside),
    // kept while the same solids move: a paddle turning in a mesh bowl tests the bowl once.
    std::vector<bool> moved;           // the solids that moved, as the kept samples were taken
    std::vector<uint64_t> still_inside;  // kReachWords a node
    std::vector<bool> still_taken;     // a node's kept samples taken
    int count() const { return nodes.x * nodes.y * nodes.z; }
    int per_colour() const { return (nodes.x + 1) / 2 * nodes.y * nodes.z; }  // coarse_sweep.comp's threads
    int index(glm::ivec3 p) const { return (p.z * nodes.y + p.y) * nodes.x + p.x; }  // coarse.glsl's node_index
    glm::ivec3 node(int k) const { return {k % nodes.x, (k / nodes.x) % nodes.y, k / (nodes.x * nodes.y)}; }
  } coarse;
  SolverParams solver;
  WhiteWaterParams white_water;  // max_particles resolved
  std::vector<ParamKey> shader_keys;  // the keys of `solver` and `white_water`, offered to every pass
  double keep_out = 0;  // m: how far particle centres stay from every solid's surface, half a spacing
  std::vector<Obstacle> obstacles;  // grown by keep_out: where particle centres may not be
  std::vector<Body> bodies;         // rigid bodies, each one of the obstacles (Obstacle::body)
  // Whether the box's walls mirror the fluid: not where the domain is a mesh (Obstacle::container),
  // which is then the tank; the walls still keep every particle inside the box.
  bool walls_mirror = true;
  // The tank's motion (its shaking, turning, a viewer's tilt): the solvers work in the tank's
  // frame, where the fluid feels g less the tank's acceleration and, where it turns, the
  // rotating frame's terms, given each step as the velocity it changes by (TankMotion::step_to).
  TankMotion tank;
  TankKick tank_kick;
  // g as the tank's frame feels it over the last step, turned and less the tank's acceleration,
  // its rotation's terms left out: what white water falls by (shaders/solids.glsl).
  glm::dvec3 tank_gravity() const { return gravity + (moving() ? tank_kick.linear / dt : glm::dvec3(0.0)); }
  // A live run's (pbflow serve): a viewer may drag any obstacle and shake the tank, so the
  // solvers are made for moving solids whether or not the scene moves any.
  bool steerable = false;
  void make_steerable();
  bool moving() const;  // whether any obstacle moves, or the tank, or a viewer may move them
  bool sticky() const;  // whether the fluid sticks to any obstacle (Obstacle::slip false)
  // Obstacle k's placement shifted by `shift` (m, from where the scene places it), reached at
  // most kSolidStep spacings a step less what its own motion takes (steerable only); a body is
  // held by the hand (Obstacle::held) until released.
  void drag(size_t k, const glm::dvec3& shift);
  void release(size_t k);  // a body the hand let go: its dynamics move it on from the hand's velocity
  // The tank shaken by m from the step's end `now`; a tilt under way is timed again beside it.
  void shake(const Motion& m, double now);
  // The tank turned to `to` from the step's end `now`, eased over a second or what keeps its walls
  // within kSolidStep spacings a step beside its own motion (smoothstep's peak rate is 1.5 times
  // its mean).
  void tilt(const glm::dquat& to, double now);
  // The solids of this scene and its bodies' velocities as another solver holds them
  // (Solver::carry), their open shares measured anew; kept steerable where this is.
  void carry_solids(const std::vector<Obstacle>& placed, const TankMotion& motion, const std::vector<Body>& moving);
  std::vector<Pose> obstacle_poses() const;  // where each stands now
  // The tank to time t, the end of a step: the step's kick (tank_kick), which the fluid and the
  // bodies (BodyCoupling::predict) take.
  void step_tank(double t) { tank_kick = tank.step_to(t, dt, gravity); }
  // The obstacles moved to their poses at time t, the end of a step, and the coarse nodes'
  // open shares measured again where a moving one reaches (at its start pose or its end);
  // whether any were (the tank's shaking alone leaves them).
  bool move_solids(double t);
  void hold_solids();  // every solid where it is and still, the tank unshaken, for a step
  // The distance from x to the nearest moving obstacle's own surface (infinity where none
  // moves), its outward normal and the velocity of the solid's point at x over the step.
  double nearest_moving_solid(const glm::dvec3& x, glm::dvec3& normal, glm::dvec3& velocity) const;
  // The coarse nodes' open shares (Coarse::open) of the nodes within `reach` of a point in
  // `near` (every node where `near` is empty); `moved` flags the obstacles that moved (none
  // where it is empty).
  struct Reach {
    glm::dvec3 centre;
    double radius;
  };
  void measure_open(const std::vector<Reach>& near, const std::vector<bool>& moved = {});
  double speed_limit;  // m/s: the divergence watch stops a run with a particle faster than this
  // m/s: the scale of the scene's flows, a fall through the domain's height (at least 0.1 m/s:
  // a scene without gravity has one too), white water's unit of speed (shaders/white_water.h).
  double flow_speed;

  SimConstants to_gpu(uint32_t count) const;

  // Water in and out (sim/flow.hpp): the emitters (their layers' count is the solvers' state),
  // the drains, and the most particles a run holds at once (capacity_for).
  std::vector<Emitter> emitters;
  std::vector<Drain> drains;
  int stated_capacity = 0;  // the scene's capacity; 0: chosen
  bool emitting = true;     // the emitters on (a viewer's switch, Solver::set_emitting)
  double run_seconds = 0;   // the scene's frames / fps: what the chosen capacity covers
  bool flows() const { return !emitters.empty() || !drains.empty(); }
  // The capacity for a run starting with `start` particles: the scene's, else the start and every
  // layer the emitters bring up to run_seconds (none drained), within kMaxParticles. A stated
  // capacity below the start and the emitters' first layers is bad input (InputError).
  size_t capacity_for(size_t start) const;
  FlowFrame flow_frame(size_t capacity) const;
  // The domain's lowest corner along g: where potential energy is measured from (reduce_stats.comp).
  glm::dvec3 lowest() const {
    return glm::mix(domain_min, domain_max, glm::dvec3(glm::greaterThan(gravity, glm::dvec3(0.0))));
  }
};

// The lambda averages a pair of iterations gets unless the scene says: four from three
// iterations on where a step moves at most h (travel <= 1), else two (params.cpp says why).
int default_smoothing(int iterations, double travel);

// A list holds the neighbours of fluid squeezed to this multiple of rho0. The default scenes
// stay under 1.3x at the real-time step; only a collapsing column (docs/physics.md) passes 2x.
constexpr double kNeighbourHeadroom = 2.0;

// The coarse node nearest x: the centre of the cell it lies in (shaders/coarse.glsl).
inline int coarse_node_at(const Derived& d, const glm::dvec3& x) {
  const glm::ivec3 cell = glm::ivec3(glm::floor((x - d.wall_min) / d.coarse.cell));
  return d.coarse.index(glm::clamp(cell, glm::ivec3(0), d.coarse.nodes - 1));
}

// The eight coarse nodes around x with their trilinear weights (shaders/coarse.glsl).
template <class F>
void for_each_coarse_node(const Derived& d, const glm::dvec3& x, F&& visit) {
  const Derived::Coarse& c = d.coarse;
  const glm::dvec3 g = (x - d.wall_min) / c.cell - 0.5;  // nodes at the cells' centres
  const glm::ivec3 base = glm::ivec3(glm::floor(g));
  const glm::dvec3 t = g - glm::dvec3(base);
  for (int k = 0; k < 8; ++k) {
    const glm::ivec3 o(k & 1, (k >> 1) & 1, (k >> 2) & 1);
    const glm::ivec3 node = glm::clamp(base + o, glm::ivec3(0), c.nodes - 1);
    const double w = (o.x ? t.x : 1 - t.x) * (o.y ? t.y : 1 - t.y) * (o.z ? t.z : 1 - t.z);
    visit(c.index(node), w);
  }
}

}  // namespace pbflow
