#pragma once
// A solid of any shape as a signed distance field on a grid (built from a mesh by
// scene/mesh_field.cpp): negative inside, read trilinearly (sample: sim/solids/obstacles.cpp). The GPU reads the same values
// (shaders/solids.glsl, field_distance) from the obstacles' buffer.
#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace pbflow {

struct DistanceField {
  glm::dvec3 origin{0.0};  // the position of value (0, 0, 0)
  double voxel = 0;        // the grid's spacing, m
  glm::ivec3 dims{0};      // values along each axis, at least 2
  std::vector<float> values;  // x fastest, then y, then z
  // A bit per value, 32 a word: whether a concave crease or corner of the surface lies within
  // a kernel of that node or its neighbours (mark_creases, sim/solids/mirrors.hpp); the
  // mirrors look for one's faces only there.
  std::vector<uint32_t> creases;

  size_t index(glm::ivec3 p) const { return size_t((p.z * dims.y + p.y) * dims.x + p.x); }  // node p's value's
  float at(glm::ivec3 p) const { return values[index(p)]; }
  glm::dvec3 extent() const { return origin + voxel * glm::dvec3(dims - 1); }
  // The trilinear distance at x and its gradient; outside the grid, the value at the nearest
  // point of the grid plus the distance to it (the grid reaches past every kernel: no more is
  // needed there).
  double sample(const glm::dvec3& x, glm::dvec3& gradient) const;
  // Whether the node nearest x is marked in `creases` (none is beyond the grid).
  bool near_crease(const glm::dvec3& x) const;
};

}  // namespace pbflow
