#include "scene/mesh.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <utility>

#include "common/input_error.hpp"
#include "common/read_file.hpp"
#include "sim/solids/motion.hpp"

namespace pbflow {

namespace {

// Every edge of a closed mesh borders exactly two triangles (their winding is not checked).
bool closed(const aiMesh& m) {
  std::map<std::pair<unsigned, unsigned>, int> edges;
  for (unsigned f = 0; f < m.mNumFaces; ++f)
    for (int e = 0; e < 3; ++e) {
      const unsigned a = m.mFaces[f].mIndices[e], b = m.mFaces[f].mIndices[(e + 1) % 3];
      edges[{std::min(a, b), std::max(a, b)}] += 1;
    }
  for (const auto& [edge, count] : edges)
    if (count != 2) return false;
  return true;
}

const aiScene* import(Assimp::Importer& importer, const std::string& bytes, const std::string& extension,
                      const std::string& what) {
  const aiScene* scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(),
                                                     aiProcess_Triangulate | aiProcess_JoinIdenticalVertices, extension.c_str());
  if (!scene) throw InputError(what + " cannot be read as a mesh: " + importer.GetErrorString());
  return scene;
}

}  // namespace

TriangleMesh read_mesh(const std::string& path, const std::string& what, const Placement& placement) {
  const std::string bytes = read_user_file(path, what, {kMaxMeshBytes});
  std::string extension = std::filesystem::path(path).extension().string();
  return parse_mesh(bytes, extension.empty() ? "" : extension.substr(1), what, placement);
}

TriangleMesh parse_mesh(const std::string& bytes, const std::string& extension, const std::string& what,
                        const Placement& placement) {
  Assimp::Importer importer;
  const aiScene* scene = import(importer, bytes, extension, what);
  const glm::dmat3 turn = euler_rotation(placement.rotation);
  TriangleMesh out;
  for (unsigned k = 0; k < scene->mNumMeshes; ++k) {
    const aiMesh& m = *scene->mMeshes[k];
    if (!(m.mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    if (out.triangles.size() + m.mNumFaces > kMaxMeshTriangles)
      throw InputError(what + " has more than " + std::to_string(kMaxMeshTriangles) + " triangles");
    if (!closed(m)) throw InputError(what + " is not closed (an edge not shared by exactly two triangles): a solid needs an inside");
    const int first = int(out.vertices.size());
    for (unsigned v = 0; v < m.mNumVertices; ++v) {
      const glm::dvec3 p(m.mVertices[v].x, m.mVertices[v].y, m.mVertices[v].z);
      if (glm::any(glm::isnan(p)) || glm::any(glm::isinf(p))) throw InputError(what + " has a vertex that is not a finite number");
      out.vertices.push_back(placement.position + turn * (placement.scale * p));
    }
    for (unsigned f = 0; f < m.mNumFaces; ++f) {
      const aiFace& face = m.mFaces[f];
      if (face.mNumIndices == 3)
        out.triangles.emplace_back(first + int(face.mIndices[0]), first + int(face.mIndices[1]), first + int(face.mIndices[2]));
    }
  }
  if (out.triangles.empty()) throw InputError(what + " holds no triangles");
  out.lo = out.hi = out.vertices[0];
  for (const glm::dvec3& p : out.vertices) out.lo = glm::min(out.lo, p), out.hi = glm::max(out.hi, p);
  return out;
}

}  // namespace pbflow
