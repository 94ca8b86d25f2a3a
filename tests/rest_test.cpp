// A tank at rest at its own spacing (0.02 m) and step (60 fps x 2 substeps): 0.4 m deep
// like the hydrostatic scene, a smaller cross-section (0.3 x 0.2 m, 3000 particles) to
// keep CI short. It must lose energy, stay inside, and come nearly to rest.
#include <cmath>

#include "gpu_solver.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

struct Setting {
  const char* method;
  int iterations;
};
void PrintTo(const Setting& s, std::ostream* os) { *os << s.method << "@" << s.iterations; }

// Measured here (README "Physics at the real-time step"): max speed at 2 s 0.2-0.7 m/s and
// mean compression 6-14 % for these settings: a soft, slowly sloshing column, not the
// 0.1 m/s that DESIGN.md asks for (not met; stated in the README). The bounds fail for the
// solver before the relaxation (7-9 m/s, or a blow-up) and for any energy-making one.
constexpr double kMaxSpeed = 1.0, kMeanCompression = 0.2;

class RestTest : public test::GpuTest, public ::testing::WithParamInterface<Setting> {};

TEST_P(RestTest, TankLosesEnergyAndSettles) {
  const Setting& p = GetParam();
  Scene scene = load_scene("hydrostatic", {"domain.max=[0.3,0.6,0.2]", "fluid_blocks=[{\"min\":[0,0,0],\"max\":[0.3,0.4,0.2]}]",
                                           std::string("solver.method=\"") + p.method + "\"",
                                           "solver.iterations=" + std::to_string(p.iterations)});
  ASSERT_EQ(scene.solver.substeps, 2);
  ASSERT_EQ(scene.particle_spacing, 0.02);
  Derived d = derive(scene);
  GpuSolver solver(test::gpu(), d, initial_particles(scene));
  FrameStats s = solver.advance(0);
  EnergyGain energy;
  energy.add(s);
  for (int f = 0; f < int(2.0 * scene.fps); ++f) {
    s = solver.advance(scene.solver.substeps);
    ASSERT_FALSE(s.divergence.any()) << "frame " << f;
    energy.add(s);
  }
  const double worst_gain = energy.largest();
  std::printf("  %s@%d after 2 s: max speed %.3f m/s, mean compression %.4f, energy gain %+.4f\n", p.method,
              p.iterations, s.max_speed, s.mean_compression, worst_gain);
  EXPECT_LE(worst_gain, 0.01);
  EXPECT_LT(s.max_speed, kMaxSpeed);
  EXPECT_LT(s.mean_compression, kMeanCompression);
  for (const glm::dvec3& x : solver.download().x)
    ASSERT_TRUE(glm::all(glm::greaterThanEqual(x, d.wall_min - 1e-6)) && glm::all(glm::lessThanEqual(x, d.wall_max + 1e-6)))
        << "a particle left the tank";
}

INSTANTIATE_TEST_SUITE_P(RealStep, RestTest,
                         ::testing::Values(Setting{"ldc", 1}, Setting{"pbf", 2}, Setting{"pbf", 3}),
                         [](const auto& info) {
                           return std::string(info.param.method) + std::to_string(info.param.iterations);
                         });

}  // namespace
}  // namespace pbflow
