// The walls are mirrors: a lattice at rest reads rho0 beside faces, edges and corners as inside
// the fluid, at the scene's own spacing and a coarser one (docs/physics.md, "Walls as mirrors").

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "gpu/gpu_solver.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

class WallTest : public test::GpuTest, public testing::WithParamInterface<double> {};

// The walls are mirrors: a lattice at rest reads rho0 next to faces, edges and corners as
// in the interior (the layer model before them read up to 0.9 % low at corners, and the
// continuous slab before that +2.6 % at faces). And they mirror only the fluid that is
// there: the free surface reads the same next to a wall as in the middle of the tank
// (the layer model counted a full lattice behind the wall up to its top and pushed the
// surface particles off the walls).
TEST_P(WallTest, ALatticeAtRestReadsRho0AtTheWalls) {
  const double spacing = GetParam();
  Scene scene = load_scene("hydrostatic", {"particle_spacing=" + std::to_string(spacing)});
  Derived d = derive(scene);
  GpuSolver solver(test::gpu(), d, lattice_particles(scene));
  solver.advance(0);
  ParticleState s = solver.download();
  const double top = 0.4 - 0.5 * spacing;  // the lattice's top layer
  double worst[4] = {0, 0, 0, 0};          // by the number of walls within h
  double surface_middle = 0, surface_wall_worst = 0;
  for (size_t i = 0; i < s.x.size(); ++i) {
    int walls = 0;
    for (int a : {0, 2}) walls += (s.x[i][a] - d.domain_min[a] < d.h) + (d.domain_max[a] - s.x[i][a] < d.h);
    if (s.x[i].y > 0.4 - d.h) {  // near the free surface: it lacks neighbours by nature
      if (std::abs(s.x[i].y - top) > 1e-6) continue;
      if (walls == 0) surface_middle = s.rho[i];
      else surface_wall_worst = std::max(surface_wall_worst, s.rho[i]);
      continue;
    }
    walls += s.x[i].y - d.domain_min.y < d.h;
    worst[std::min(walls, 3)] = std::max(worst[std::min(walls, 3)], std::abs(s.rho[i] / d.rho0 - 1));
  }
  std::printf("  |rho/rho0 - 1| at most: interior %.2e, face %.2e, edge %.2e, corner %.2e; top layer %.2f (middle), "
              "%.2f (at walls, largest)\n",
              worst[0], worst[1], worst[2], worst[3], surface_middle / d.rho0, surface_wall_worst / d.rho0);
  for (double w : worst) EXPECT_LT(w, 1e-4);  // float sums
  ASSERT_GT(surface_middle, 0.0);
  EXPECT_LT(surface_wall_worst / surface_middle - 1, 1e-4);
}

// The smoothed positions the fluid's surface is drawn from (smoothed_positions.comp): a lattice
// at rest keeps its interior and its particles at the walls where they are, the walls' images
// completing their neighbourhoods, and only the free surface moves, inward, by less than a
// spacing. Without the images the wall layers would be drawn a fraction of a spacing off
// the walls, and a tank's water would stand clear of its glass.
TEST_P(WallTest, SmoothedPositionsMoveOnlyTheFreeSurface) {
  const double spacing = GetParam();
  Scene scene = load_scene("hydrostatic", {"particle_spacing=" + std::to_string(spacing)});
  Derived d = derive(scene);
  GpuSolver solver(test::gpu(), d, lattice_particles(scene));
  solver.set_outputs({.surface = true});
  solver.advance(0);
  const ParticleFrame f = solver.read_frame();
  ASSERT_EQ(f.x_smooth.size(), f.x.size());
  const double rounding = 1e-6;  // m: a few float ulps of coordinates under 1 m, summed over ~30 neighbours
  double below_surface = 0, surface_least = 1e9, surface_most = 0;
  for (size_t k = 0; k < f.x.size(); ++k) {
    const glm::dvec3 x(glm::vec3(f.x[k])), moved = glm::dvec3(glm::vec3(f.x_smooth[k])) - x;
    if (x.y < 0.4 - d.h) {
      below_surface = std::max(below_surface, glm::length(moved));
    } else if (std::abs(x.y - (0.4 - 0.5 * spacing)) < 1e-6) {  // the top layer
      EXPECT_LT(std::abs(moved.x) + std::abs(moved.z), rounding) << "a top particle moved sideways";
      surface_least = std::min(surface_least, -moved.y);
      surface_most = std::max(surface_most, -moved.y);
    }
  }
  std::printf("  moved, in spacings: below the surface at most %.1e; the top layer down by %.3f to %.3f\n",
              below_surface / spacing, surface_least / spacing, surface_most / spacing);
  EXPECT_LT(below_surface, rounding);
  EXPECT_GT(surface_least, 0.05 * spacing);
  EXPECT_LT(surface_most, 0.5 * spacing);
  EXPECT_LT(surface_most - surface_least, rounding);  // at the walls as in the middle
}

INSTANTIATE_TEST_SUITE_P(Spacings, WallTest, testing::Values(0.02, 0.05));

}  // namespace
}  // namespace pbflow
