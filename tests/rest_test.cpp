// A block of fluid at rest in a tank stays at rest: after 2 s of simulated time the
// fluid has settled (bounded speed) without compressing, for both methods.
#include "gpu_solver.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

// Bounds measured on the hydrostatic tank at 0.05 m spacing (8 layers, 1152 particles);
// see README "Accuracy at rest". They leave ~2x headroom over the measured values and
// fail for a solver that compresses, drifts or blows up.
constexpr double kMaxSpeed = 1.0;           // m/s (free fall over the 0.4 m depth: 2.8 m/s)
constexpr double kMeanCompression = 0.02;   // 2 %
constexpr double kMaxCompression = 0.15;

class RestTest : public test::GpuTest, public ::testing::WithParamInterface<const char*> {};

TEST_P(RestTest, TankStaysAtRestFor2Seconds) {
  Scene scene = test::test_scene("hydrostatic", {"particle_spacing=0.05", std::string("solver.method=\"") + GetParam() + "\""});
  Derived d = derive(scene);
  GpuSolver solver(test::gpu(), d, initial_particles(scene));
  FrameStats s;
  int frames = int(2.0 * scene.fps);
  for (int f = 0; f < frames; ++f) s = solver.advance(scene.solver.substeps);
  std::printf("  %s after 2 s: max speed %.3f m/s, mean compression %.5f, max compression %.4f\n", GetParam(),
              s.max_speed, s.mean_compression, s.max_compression);
  EXPECT_LT(s.max_speed, kMaxSpeed);
  EXPECT_LT(s.mean_compression, kMeanCompression);
  EXPECT_LT(s.max_compression, kMaxCompression);
  for (const glm::dvec3& x : solver.download().x) {
    ASSERT_TRUE(glm::all(glm::greaterThanEqual(x, d.wall_min - 1e-6)) && glm::all(glm::lessThanEqual(x, d.wall_max + 1e-6)))
        << "a particle left the tank";
  }
}

INSTANTIATE_TEST_SUITE_P(Methods, RestTest, ::testing::Values("pbf", "ldc"));

}  // namespace
}  // namespace pbflow
