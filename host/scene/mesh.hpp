#pragma once
// Solids brought as triangle meshes (OBJ, STL, PLY): read by assimp, placed in the scene, checked
// closed, and turned into a signed distance field by OpenVDB (mesh_field.cpp), which the solver
// reads as any other solid (sim/solids/distance_field.hpp).
#include <glm/glm.hpp>

#include <memory>
#include <string>
#include <vector>

#include "sim/solids/distance_field.hpp"

namespace pbflow {

constexpr long long kMaxMeshBytes = 256LL << 20;   // a mesh file larger is refused before it is read
constexpr size_t kMaxMeshTriangles = 2'000'000;    // and one with more triangles after
constexpr size_t kMaxFieldValues = size_t(1) << 24;  // 64 MiB of distance field at most

struct Placement {
  glm::dvec3 scale{1.0};
  glm::dvec3 position{0.0};
  glm::dvec3 rotation{0.0};  // degrees about x, then y, then z, the axes fixed (extrinsic)
};

struct TriangleMesh {
  std::vector<glm::dvec3> vertices;
  std::vector<glm::ivec3> triangles;
  glm::dvec3 lo{0.0}, hi{0.0};  // its bounding box
};

// The mesh in `path` (`what` names it in messages), placed; an InputError when it cannot be
// read, is empty, has a vertex that is not finite, too many triangles, or is not closed (an edge
// not shared by exactly two triangles).
TriangleMesh read_mesh(const std::string& path, const std::string& what, const Placement& placement);
// The same from a file's bytes, `extension` its format (obj, stl, ply).
TriangleMesh parse_mesh(const std::string& bytes, const std::string& extension, const std::string& what,
                        const Placement& placement);

// Its signed distance field (negative inside) on a grid `voxel` apart reaching `reach` past
// the mesh on every side; an InputError where the grid would pass kMaxFieldValues.
std::shared_ptr<DistanceField> mesh_field(const TriangleMesh& mesh, double voxel, double reach,
                                                const std::string& what);

}  // namespace pbflow
