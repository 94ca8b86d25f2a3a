#pragma once
// Static obstacles: axis-aligned boxes, spheres and meshes (as distance fields) that particles
// are projected out of, like the walls, and that mirror the fluid (sim/mirrors.hpp). The solver keeps particle
// centres half a spacing away from an obstacle's surface, so it works with each shape grown
// by that margin (Derived::keep_out). shaders/solids.glsl mirrors this file.
#include <glm/glm.hpp>

#include <memory>
#include <vector>

#include "sim/distance_field.hpp"

namespace pbflow {

struct Obstacle {
  enum class Kind { Box, Sphere, Mesh } kind = Kind::Box;
  glm::dvec3 min{0.0}, max{0.0};  // box; a mesh's bounds
  glm::dvec3 centre{0.0};         // sphere
  double radius = 0;
  std::shared_ptr<const DistanceField> field;  // mesh: the surface is its zero ...
  double margin = 0;                           // ... moved out by this much (grown)

  bool contains(const glm::dvec3& x) const;   // strictly inside
  Obstacle grown(double margin) const;        // every surface moved out by margin
  // The signed distance from x to the surface (negative inside) and the outward normal at
  // the surface point nearest x; inside a box, the nearest face's.
  double surface(const glm::dvec3& x, glm::dvec3& normal) const;
};

// x moved onto the nearest surface of `o` if it is inside. For a box, only faces
// between the walls are candidates, so that the walls' clamp cannot push the particle
// back in (a box standing on the floor pushes up or sideways, never down).
glm::dvec3 project_out(const Obstacle& o, const glm::dvec3& x, const glm::dvec3& wall_min,
                       const glm::dvec3& wall_max);

// Where the move from -> to first enters `o`: the entry point, or `to` when the segment
// misses it. Keeps a fast particle from tunnelling through a thin obstacle within one
// step; project_out then settles it on the surface. A start within `contact` of the
// obstacle counts as touching it and is left to project_out, so that rounding (float on
// the GPU, double here) cannot decide between the two.
glm::dvec3 stop_at(const Obstacle& o, const glm::dvec3& from, const glm::dvec3& to, double contact);

// The share outside every solid of the tent (1 - |t|) per axis about `centre`, `reach` to each
// side, from (2 samples)^3 points: what a node of the coarse grid can gather of a uniform fluid,
// against what it would with no solids (Derived::Coarse::open).
double open_fraction(const std::vector<Obstacle>& solids, const glm::dvec3& centre, const glm::dvec3& reach, int samples);

// The GPU layout: vec4 0 holds the count and the keep-out margin the shapes are grown by;
// then three vec4 per obstacle: box (min, 0) (max, 0) (0); sphere (centre, 1) (radius, 0, 0, 0)
// (0); mesh (field origin, 2) (dims, voxel) (first value, 0, 0, 0); then the meshes' field
// values, four a vec4, value 0 at vec4 1 + 3 count.
std::vector<glm::vec4> pack_obstacles(const std::vector<Obstacle>& obstacles, double margin);
size_t packed_obstacle_vec4s(const std::vector<Obstacle>& obstacles);  // its length, without packing

}  // namespace pbflow
