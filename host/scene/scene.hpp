#pragma once
// A scene as pbflow holds it once parsed (scene/parse.hpp reads it from JSON), and the
// measures of it that are known before any particle is made.
#include <glm/glm.hpp>

#include <string>
#include <vector>

#include "common/input_error.hpp"
#include "sim/flow.hpp"
#include "sim/solids/bodies.hpp"
#include "sim/solids/obstacles.hpp"
#include "sim/params.hpp"

namespace pbflow {

// The most frames a run may write (as --frames): far past any real run, well inside int.
constexpr int kMaxFrames = 100000000;
// The largest scene file read: 100 000 obstacles take about 10 MiB of JSON.
constexpr long long kMaxSceneBytes = 64LL << 20;

struct Box {
  glm::dvec3 min, max;
  // Corner k of 8: bit 0 picks max.x, bit 1 max.y, bit 2 max.z.
  glm::dvec3 corner(int k) const {
    return {k & 1 ? max.x : min.x, k & 2 ? max.y : min.y, k & 4 ? max.z : min.z};
  }
  glm::dvec3 floor_centre() const { return {0.5 * (min.x + max.x), min.y, 0.5 * (min.z + max.z)}; }
};

struct Ball {
  glm::dvec3 centre;
  double radius;
};

struct Camera {
  glm::dvec3 eye, target;
  double fov_degrees;
};

struct Scene {
  std::string name;
  std::string description;
  std::string resolved;  // the scene as read, overrides applied: JSON text (DIR/run.json)
  Box domain;
  double particle_spacing;
  std::vector<Box> fluid_blocks;
  std::vector<Ball> fluid_spheres;
  std::vector<Obstacle> obstacles;  // the scene's, then each body's (Obstacle::body), then the domain's mesh
  std::vector<Body> bodies;
  std::vector<Emitter> emitters;  // sim/flow.hpp; inlet points made by derive()
  std::vector<Drain> drains;
  int capacity = 0;  // 0: chosen (Derived::capacity)
  Motion tank_motion;  // domain.motion: the tank shaken (translation only)
  glm::dvec3 gravity;
  // The fluid starts at rest in the solver's own equilibrium (host/sim/settle.hpp): for a tank,
  // not for a drop in the air (every particle settles along gravity).
  bool settle = false;
  int seed;  // of the start's jitter (scene/seeding.hpp)
  double fps;
  int frames;
  SolverParams solver;
  WhiteWaterParams white_water;
  Camera camera;
  bool camera_framed = false;  // the scene named no eye: framing_camera chose it
};

// The fluid's volume as the scene states it (blocks and spheres, overlaps counted twice),
// m^3: the particle-count estimate before any particle is made.
double fluid_volume(const Scene& scene);
// fluid_volume / spacing^3: the particles a scene will hold, known before any is made.
double particle_estimate(const Scene& scene);
// The speed of a fall from rest through the domain's height, sqrt(2 |g| H), m/s: the
// scale of the scene's flows (time-step check, divergence watch, speed colours).
double fall_speed(const Scene& scene);

// The fastest any moving solid's surface, or the tank's walls, moves, m/s (Motion::top_speed): 0
// where nothing moves.
double solid_speed(const Scene& scene);
double tank_speed(const Scene& scene);  // the tank's walls' alone
// The substeps a scene that leaves them out gets: the fewest that keep dt at most 1/120 s
// (the real-time step at 60 fps), a particle falling through the domain or leaving an emitter
// within one kernel radius a step (the time-step check of derive.hpp) and every moving solid within kSolidStep
// spacings a step; at most 1000.
int chosen_substeps(const Scene& scene);

}  // namespace pbflow
