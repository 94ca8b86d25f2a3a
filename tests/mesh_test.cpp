// Meshes as solids (scene/mesh.hpp): a mesh's distance field is its distance, and a mesh that
// cannot be a solid is refused with a line naming it.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include <unistd.h>

#include "common/input_error.hpp"
#include "scene/mesh.hpp"
#include "scene/parse.hpp"

namespace pbflow {
namespace {

const std::string kMeshes = std::string(PBFLOW_TEST_DATA) + "/../scenes/meshes/";

// The icosphere (radius 0.1, 1280 faces, its flat faces at most 0.3 mm inside the sphere) read
// at half a 0.02 m spacing: within a millimetre of the ball's distance where the passes read
// distances (out to h past the surface, a little inside). Deeper inside only its sign is read
// (images inside, the coarse grid's open share); OpenVDB's inside reads up to 1.5 mm off there.
TEST(MeshField, ABallsFieldIsItsDistance) {
  const TriangleMesh mesh = read_mesh(kMeshes + "ball.obj", "ball", {});
  EXPECT_EQ(mesh.triangles.size(), 1280u);
  const auto field = mesh_field(mesh, 0.01, 0.06, "ball");
  std::mt19937 random(65);
  std::uniform_real_distribution<double> unit(-1, 1);
  double worst = 0;
  for (int k = 0; k < 2000; ++k) {
    const glm::dvec3 u = glm::normalize(glm::dvec3(unit(random), unit(random), unit(random)));
    const glm::dvec3 x = (0.1 + 0.02 + 0.03 * unit(random)) * u;  // from 1 cm inside to 5 cm out
    glm::dvec3 gradient;
    worst = std::max(worst, std::abs(field->sample(x, gradient) - (glm::length(x) - 0.1)));
    EXPECT_GT(glm::dot(glm::normalize(gradient), u), 0.95) << "the normal at " << k;
  }
  std::printf("  |field - distance| at most %.2e m\n", worst);
  EXPECT_LT(worst, 1e-3);
}

// Every mesh the project ships (scripts/make_meshes.py) is closed and wound outward: its field
// is negative at a point inside it and positive just beyond its bounds.
TEST(MeshField, EveryShippedMeshIsASolidWoundOutward) {
  const std::pair<const char*, glm::dvec3> inside[] = {{"ball.obj", {0, 0, 0}},     {"rock.obj", {0, 0, 0}},
                                                       {"cup.obj", {0, 0.01, 0}},   {"bowl.obj", {0, 0.2, 0}},
                                                       {"paddle.obj", {0, 0.1, 0}}, {"hull.obj", {0, -0.03, 0}}};
  for (const auto& [name, point] : inside) {
    const TriangleMesh mesh = read_mesh(kMeshes + name, name, {});
    const auto field = mesh_field(mesh, 0.01, 0.04, name);
    glm::dvec3 gradient;
    EXPECT_LT(field->sample(point, gradient), 0.0) << name << ": not inside at its inner point";
    EXPECT_GT(field->sample(mesh.hi + 0.02, gradient), 0.0) << name << ": inside beyond its bounds";
  }
}

class MeshInput : public ::testing::Test {
 protected:
  std::filesystem::path dir = std::filesystem::temp_directory_path() / ("pbflow_mesh_" + std::to_string(getpid()));
  void SetUp() override { std::filesystem::create_directories(dir); }
  void TearDown() override { std::filesystem::remove_all(dir); }
  // The error a scene with mesh `text` (written to `name`) in its obstacles gives, or "".
  // A null `text` writes no file.
  std::string error(const std::string& name, const char* text, const std::string& extra = "") {
    if (text) std::ofstream(dir / name) << text;
    const std::string scene = R"({"domain": {"min": [0,0,0], "max": [1,1,1]}, "particle_spacing": 0.05,
      "fluid_blocks": [{"min": [0,0,0], "max": [1,0.5,1]}], "obstacles": [{"type": "mesh", "file": ")" +
                              (dir / name).string() + "\"" + extra + "}]}";
    try {
      parse_scene(scene, "scene", {});
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
};

constexpr const char* kTetrahedron = "v 0.4 0.4 0.4\nv 0.6 0.4 0.4\nv 0.4 0.6 0.4\nv 0.4 0.4 0.6\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

TEST_F(MeshInput, AClosedMeshIsASolidAndABadOneANamedError) {
  EXPECT_EQ(error("tetra.obj", kTetrahedron), "");
  EXPECT_NE(error("open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").find("is not closed"), std::string::npos);
  const std::string nan = std::string(kTetrahedron) + "v nan 0.5 0.5\nv 0.6 0.5 0.5\nv 0.5 0.6 0.5\nv 0.5 0.5 0.6\n"
                          "f 5 7 6\nf 5 6 8\nf 5 8 7\nf 6 7 8\n";
  EXPECT_NE(error("nan.obj", nan.c_str()).find("not a finite"), std::string::npos);
  EXPECT_NE(error("empty.obj", "").find("empty.obj"), std::string::npos);
  EXPECT_NE(error("junk.stl", "solid junk\nfacet nonsense\n").find("junk.stl"), std::string::npos);
  EXPECT_NE(error("missing.obj", nullptr).find("cannot read"), std::string::npos);
  EXPECT_NE(error("far.obj", kTetrahedron, R"(, "position": [5, 5, 5])").find("outside the domain"), std::string::npos);
  EXPECT_NE(error("key.obj", kTetrahedron, R"(, "colour": 1)").find("unknown scene key 'obstacles[0].colour'"),
            std::string::npos);
  EXPECT_NE(error("scale.obj", kTetrahedron, R"(, "scale": [1, 0, 1])").find("scale' must be positive"), std::string::npos);
}

}  // namespace
}  // namespace pbflow
