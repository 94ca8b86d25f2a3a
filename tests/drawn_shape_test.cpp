// The shapes the fluid's surface draws its particles with (smoothed_positions.comp, Yu & Turk
// 2013's anisotropy; docs/rendering.md): spheres inside the fluid and at the walls, discs at a
// free surface, ellipsoids stretched along a sheet whose rows a flow has pulled apart, and
// spheres for spray. The GPU agrees with the reference (PassTest.SmoothedPositions); these
// check what the shapes are for.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "gpu/gpu_solver.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

class DrawnShapeTest : public test::GpuTest {
 protected:
  // The drawn shapes (ellipsoid matrices in particle radii) of `x` at rest in the hydrostatic
  // tank, by particle id.
  std::vector<glm::dmat3> shapes(const std::vector<glm::dvec3>& x) {
    GpuSolver solver(test::gpu(), d, x);
    solver.set_outputs({.surface = true});
    solver.advance(0);
    const ParticleFrame f = solver.read_frame();
    std::vector<glm::dmat3> t(x.size());
    for (size_t k = 0; k < f.id.size(); ++k) t[f.id[k]] = decode_shape(f.shape[2 * k], f.shape[2 * k + 1]);
    return t;
  }
  static double off_diagonal(const glm::dmat3& t) { return std::abs(t[1][0]) + std::abs(t[2][0]) + std::abs(t[2][1]); }

  Scene scene = load_scene("hydrostatic");
  Derived d = derive(scene);
  double s = scene.particle_spacing;
};

// The tank's lattice: inside and against the walls (their images complete the neighbourhood)
// a sphere; the top layer a disc, thin along y, of the sphere's volume.
TEST_F(DrawnShapeTest, ALatticeIsSpheresInsideAndDiscsAtItsTop) {
  const std::vector<glm::dvec3> x = lattice_particles(scene);
  const std::vector<glm::dmat3> t = shapes(x);
  double top = 0, inside_worst = 0;
  for (const glm::dvec3& p : x) top = std::max(top, p.y);
  glm::dmat3 disc(0.0);
  for (size_t i = 0; i < x.size(); ++i) {
    if (x[i].y < top - d.h) {
      for (int c = 0; c < 3; ++c) inside_worst = std::max(inside_worst, glm::length(t[i][c] - glm::dmat3(1.0)[c]));
    } else if (x[i].y == top) {
      disc = t[i];
      EXPECT_LT(off_diagonal(t[i]), 1e-4) << "the top layer's discs lie level";
      EXPECT_NEAR(t[i][0][0], t[i][2][2], 1e-4) << "and round";
    }
  }
  std::printf("  below the top: |T - I| at most %.1e; a top particle: T = diag(%.3f, %.3f, %.3f)\n", inside_worst,
              disc[0][0], disc[1][1], disc[2][2]);
  EXPECT_LT(inside_worst, 1e-4);
  EXPECT_LT(std::sqrt(disc[1][1]), 0.8) << "thin along the surface's normal";
  EXPECT_GT(std::sqrt(disc[0][0]), 1.1);
  EXPECT_NEAR(glm::determinant(disc), 1.0, 1e-4) << "the sphere's volume";
}

// One layer mid-tank, its rows 1.75 spacings apart along x and a spacing along z (a spreading
// flow's top layer): the spheres, a spacing across, left a gap and a ridge per row; the drawn
// ellipsoids reach across the gap, and stay thinnest across the sheet.
TEST_F(DrawnShapeTest, ASheetPulledApartIsDrawnWithoutGaps) {
  std::vector<glm::dvec3> x;
  const double row = 1.75 * s;
  for (int i = 0; i < 10; ++i)
    for (int k = 0; k < 10; ++k) x.push_back(glm::dvec3(0.1 + i * row, 0.2, 0.1 + k * s));
  const std::vector<glm::dmat3> t = shapes(x);
  const glm::dmat3 middle = t[5 * 10 + 5];
  std::printf("  a sheet's middle particle: T = diag(%.3f, %.3f, %.3f)\n", middle[0][0], middle[1][1], middle[2][2]);
  EXPECT_LT(off_diagonal(middle), 1e-4);
  EXPECT_GE(std::sqrt(middle[0][0]) * s, row) << "an ellipsoid s * sqrt(T_xx) across reaches the next row";
  EXPECT_GT(middle[2][2], middle[1][1]);
}

// Spray (a particle alone, or a few) is drawn as spheres: a droplet, not a needle.
TEST_F(DrawnShapeTest, SprayIsDrawnAsSpheres) {
  const std::vector<glm::dvec3> x = {{0.1, 0.3, 0.1}, {0.3, 0.3, 0.3}, {0.3 + s, 0.3, 0.3}, {0.3 + 2 * s, 0.3, 0.3}};
  for (const glm::dmat3& t : shapes(x))
    for (int c = 0; c < 3; ++c) EXPECT_EQ(t[c], glm::dmat3(1.0)[c]);
}

}  // namespace
}  // namespace pbflow
