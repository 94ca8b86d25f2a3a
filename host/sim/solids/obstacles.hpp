#pragma once
// Obstacles: boxes, spheres and meshes (as distance fields) that particles are projected out
// of, like the walls, and that mirror the fluid (sim/solids/mirrors.hpp). Each is a shape in its body
// frame (where the scene places it) and a pose, which its motion moves every step. The solver
// keeps particle centres half a spacing away from an obstacle's surface, so it works with each
// shape grown by that margin (Derived::keep_out). shaders/solids.glsl mirrors this file.
#include <glm/glm.hpp>

#include <memory>
#include <span>
#include <vector>

#include "shaders/contract.h"
#include "sim/solids/distance_field.hpp"
#include "sim/solids/motion.hpp"

namespace pbflow {

struct Obstacle {
  enum class Kind { Box, Sphere, Mesh } kind = Kind::Box;
  // The shape, in the body frame:
  glm::dvec3 min{0.0}, max{0.0};  // box; a mesh's bounds
  glm::dvec3 centre{0.0};         // sphere
  double radius = 0;
  std::shared_ptr<const DistanceField> field;  // mesh: the surface is its zero ...
  double margin = 0;                           // ... moved out by this much (grown)
  std::shared_ptr<const std::vector<glm::vec3>> corners;  // mesh: its triangles, three corners each, for drawing
  // The domain's mesh (scene key domain.mesh): the solid is all outside the mesh, its field the
  // mesh's negated; it moves with the tank and is never dragged.
  bool container = false;
  // Whether the fluid slips along it (scene key "slip"); where not, the fluid beside it is
  // carried at its surface's velocity (Mirrors::stick).
  bool slip = true;
  Motion motion;
  Pose pose, previous;  // where it is at the end of the current step, and was at its start
  // A viewer's hand (pbflow serve, Derived::drag): the placement shifted by `shift`, which
  // follows `shift_to` at the speed a step keeps sound. Only a draggable obstacle has one.
  bool draggable = false;
  glm::dvec3 shift{0.0}, shift_to{0.0};
  int body = -1;  // a rigid body's solid (sim/solids/bodies.hpp): its index in Derived::bodies
  // A body a viewer's hand holds (pbflow serve, Derived::drag): it moves as a dragged solid does,
  // its middle led to where the scene placed it plus `shift_to`, and its pushes are the hand's work.
  bool held = false;
  bool dynamic() const { return body >= 0 && !held; }  // a body its dynamics move now

  bool moves() const { return draggable || motion.moves() || body >= 0; }

  bool contains(const glm::dvec3& x) const;   // strictly inside
  Obstacle grown(double margin) const;        // every surface moved out by margin
  // The signed distance from x to the surface (negative inside) and the outward normal at
  // the surface point nearest x; inside a box, the nearest face's.
  double surface(const glm::dvec3& x, glm::dvec3& normal) const;
  // A mesh's signed distance at x and its field's gradient there, not normalised: a unit vector
  // where one face is nearest, shorter within a voxel of where two meet (a crease's bisector).
  double mesh_surface(const glm::dvec3& x, glm::dvec3& gradient) const;
  // How far the solid moves at x over a step (0 for a solid that stands still): half the chord
  // from where its point at x came from to where the step's motion would take it next, so that
  // a turning surface's is along it. The chord that ends at x leans out of a turning surface by
  // R w^2 dt / 2: a frictionless ball turning in place read as swelling into the water and was
  // credited 1.3 W of work it never did (pressure times that speed, all over its surface).
  glm::dvec3 displacement(const glm::dvec3& x) const {
    return 0.5 * (pose.world(previous.body(x)) - previous.world(pose.body(x)));
  }
  // The body-frame sphere holding the shape: its centre and radius (where motion may reach).
  glm::dvec3 middle() const { return kind == Kind::Sphere ? centre : 0.5 * (min + max); }
  double extent() const { return kind == Kind::Sphere ? radius : 0.5 * glm::length(max - min); }
  // The body-frame box holding the shape: its lowest and highest corners.
  glm::dvec3 low() const { return kind == Kind::Sphere ? centre - radius : min; }
  glm::dvec3 high() const { return kind == Kind::Sphere ? centre + radius : max; }
  void move_to(const Pose& p) { previous = pose, pose = p; }

 private:
  double body_surface(const glm::dvec3& x, glm::dvec3& normal) const;  // surface() in the body frame
};

// Whether any of the solids is a mesh (a mesh's creases need a record per particle on the GPU).
bool any_mesh(const std::vector<Obstacle>& solids);

// x moved onto the nearest surface of `o` if it is inside. For a box, only faces that leave
// x between the walls are candidates, so that the walls' clamp cannot push the particle
// back in (a box standing on the floor pushes up or sideways, never down).
glm::dvec3 project_out(const Obstacle& o, const glm::dvec3& x, const glm::dvec3& wall_min,
                       const glm::dvec3& wall_max);

// Where the move from -> to first enters `o`, in its body frame (`from` at the step's start
// pose, `to` at its end): the entry point, or `to` when the segment misses it. Keeps a fast
// particle from tunnelling through a thin obstacle within one step; project_out then settles it
// on the surface. A start within `contact` of the obstacle counts as touching it and is left to
// project_out, so that rounding (float on the GPU, double here) cannot decide between the two.
// Where the fluid slips along `o` (grown by `margin`) the stop takes only the move's part into
// it, along its own surface's normal at `from` (round at a box's edges; at the point met, a
// mesh's field turns between facets and float and double parted there): the rest of the move, and
// a turning solid's, stays the particle's (a frictionless ball turning in place carried the
// particles it stopped round with it and stirred settled water at 0.16 m/s). Where the fluid
// does not slip, the particle stays where it met the surface, carried with it.
glm::dvec3 stop_at(const Obstacle& o, const glm::dvec3& from, const glm::dvec3& to, double contact, double margin);

// A node of the coarse grid gathers with the tent (1 - |t|) per axis about its centre, `reach`
// to each side, sampled at (2 COARSE_OPEN_SAMPLES)^3 points. Its open share is the tent's weight
// outside every solid against its whole weight: what it can gather of a uniform fluid, against
// what it would with no solids (Derived::Coarse::open). A bit per sample marks it inside a solid,
// so that the solids that stand still are tested once while others move.
constexpr int kReachSamples = 8 * COARSE_OPEN_SAMPLES * COARSE_OPEN_SAMPLES * COARSE_OPEN_SAMPLES;
constexpr size_t kReachWords = (kReachSamples + 63) / 64;
// Sets the bits of the samples inside `o`; samples already marked are not tested again.
void mark_inside(const Obstacle& o, const glm::dvec3& centre, const glm::dvec3& reach, std::span<uint64_t> inside);
double open_share(std::span<const uint64_t> inside);

// The GPU layout: vec4 0 holds 0 (the shaders take the count as OBSTACLE_COUNT, a specialisation
// constant) and the keep-out margin the shapes are grown by, vec4s
// 1-7 the tank's kick this step (Derived::tank_kick: linear, then of_x's and of_v's columns);
// then kObstacleVec4s per obstacle: its shape, box (min, 0) (max, 0); sphere (centre, 1)
// (radius, 0, 0, 0); mesh (field origin, 2) (dims, voxel); then (a mesh's first value or 0,
// moves, body, sticks), `moves` 1 where it has a motion, `body` its body's index + 1 where one
// moves it, `sticks` 1 where the fluid does not slip along it; then its pose and previous pose, each as the rows of the body
// transform (world to body, rotation | shift); then the meshes' field values, four a vec4, each
// mesh's followed by its crease bits (DistanceField::creases), value 0 at vec4
// obstacle_header_vec4s(count). The header (all but the field values) is what a step's
// move changes.
constexpr size_t kObstacleVec4s = OBSTACLE_VEC4S, kTankKickVec4s = TANK_KICK_VEC4S;
std::vector<glm::vec4> pack_obstacles(const std::vector<Obstacle>& obstacles, double margin,
                                      const TankKick& tank_kick = {});
std::vector<glm::vec4> pack_obstacle_header(const std::vector<Obstacle>& obstacles, double margin,
                                            const TankKick& tank_kick = {});
size_t packed_obstacle_vec4s(const std::vector<Obstacle>& obstacles);  // its length, without packing
inline size_t obstacle_header_vec4s(size_t count) { return kTankKickVec4s + 1 + kObstacleVec4s * count; }

}  // namespace pbflow
