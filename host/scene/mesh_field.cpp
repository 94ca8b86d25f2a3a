// OpenVDB's mesh to level set, alone in this file: its headers are slow to compile.
#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>

#include <algorithm>
#include <cmath>
#include <mutex>

#include "common/input_error.hpp"
#include "scene/mesh.hpp"

namespace pbflow {

std::shared_ptr<DistanceField> mesh_field(const TriangleMesh& mesh, double voxel, double reach,
                                                const std::string& what) {
  static std::once_flag initialised;
  std::call_once(initialised, [] { openvdb::initialize(); });
  // The dense grid: whole voxels from the origin, so that its nodes are OpenVDB's voxel centres.
  const glm::ivec3 first = glm::ivec3(glm::floor((mesh.lo - reach) / voxel));
  const glm::ivec3 last = glm::ivec3(glm::ceil((mesh.hi + reach) / voxel));
  const glm::dvec3 count = glm::dvec3(last - first + 1);
  if (count.x * count.y * count.z > double(kMaxFieldValues))
    throw InputError(what + "'s distance field would hold more than " + std::to_string(kMaxFieldValues) +
                     " values at half a particle spacing (raise particle_spacing or shrink the mesh)");
  std::vector<openvdb::Vec3s> points;
  for (const glm::dvec3& p : mesh.vertices) points.emplace_back(float(p.x / voxel), float(p.y / voxel), float(p.z / voxel));
  std::vector<openvdb::Vec3I> triangles;
  for (const glm::ivec3& t : mesh.triangles) triangles.emplace_back(t.x, t.y, t.z);
  // In index space (voxel 1), the band out to `reach` and the whole inside.
  const float outside = float(std::ceil(reach / voxel) + 2), inside = float(std::max({count.x, count.y, count.z}));
  const openvdb::math::Transform::Ptr index = openvdb::math::Transform::createLinearTransform(1.0);
  const openvdb::FloatGrid::Ptr grid = openvdb::tools::meshToSignedDistanceField<openvdb::FloatGrid>(
      *index, points, triangles, std::vector<openvdb::Vec4I>(), outside, inside);
  auto field = std::make_shared<DistanceField>();
  field->origin = glm::dvec3(first) * voxel;
  field->voxel = voxel;
  field->dims = last - first + 1;
  field->values.reserve(size_t(count.x * count.y * count.z));
  const openvdb::FloatGrid::ConstAccessor read = grid->getConstAccessor();
  for (int z = first.z; z <= last.z; ++z)
    for (int y = first.y; y <= last.y; ++y)
      for (int x = first.x; x <= last.x; ++x) field->values.push_back(float(voxel * read.getValue(openvdb::Coord(x, y, z))));
  return field;
}

}  // namespace pbflow
