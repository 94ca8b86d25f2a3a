// A block of fluid at rest in a tank stays at rest: after 2 s of simulated time the
// fluid has settled (bounded speeds) without compressing, for both methods.
#include <cmath>

#include "gpu_solver.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

struct Bounds {
  const char* method;
  double rms_speed, max_speed, mean_compression, max_compression;
};

// Measured on the hydrostatic tank at 0.05 m spacing (8 layers, 1152 particles) with 4
// iterations and 4 substeps, two runs (README "Accuracy at rest"):
//   pbf: rms speed 0.026-0.037 m/s, max 0.24-0.26 m/s, mean compression 5e-4, max 5e-3;
//   ldc (clamped, the default): rms speed 0.020 m/s, max 0.095 m/s, mean compression
//        5e-4, max 5e-3. The seed's unclamped force (solver.ldc_clamp=false) lifts the
//        free surface and never settles: rms 0.28-0.30 m/s, max 1.0-1.6 m/s.
// The bounds leave ~2x headroom and fail for a solver that compresses, drifts or blows up
// (free fall over the 0.4 m depth reaches 2.8 m/s). At 1 iteration and 2 substeps neither
// method settles at this resolution (rms 0.7-0.8 m/s): that is recorded, not asserted.
const Bounds kBounds[] = {
    {"pbf", 0.1, 0.6, 0.002, 0.02},
    {"ldc", 0.1, 0.6, 0.002, 0.02},
};

void PrintTo(const Bounds& b, std::ostream* os) { *os << b.method; }

class RestTest : public test::GpuTest, public ::testing::WithParamInterface<Bounds> {};

TEST_P(RestTest, TankStaysAtRestFor2Seconds) {
  const Bounds& b = GetParam();
  Scene scene = load_scene("hydrostatic", {"particle_spacing=0.05", "solver.iterations=4", "solver.substeps=4",
                                                 std::string("solver.method=\"") + b.method + "\""});
  Derived d = derive(scene);
  GpuSolver solver(test::gpu(), d, initial_particles(scene));
  FrameStats s;
  int frames = int(2.0 * scene.fps);
  for (int f = 0; f < frames; ++f) s = solver.advance(scene.solver.substeps);
  double rms_speed = std::sqrt(2.0 * s.kinetic_energy / (d.mass * solver.particle_count()));
  std::printf("  %s after 2 s: rms speed %.3f m/s, max speed %.3f m/s, mean compression %.5f, max compression %.4f\n",
              b.method, rms_speed, s.max_speed, s.mean_compression, s.max_compression);
  EXPECT_LT(rms_speed, b.rms_speed);
  EXPECT_LT(s.max_speed, b.max_speed);
  EXPECT_LT(s.mean_compression, b.mean_compression);
  EXPECT_LT(s.max_compression, b.max_compression);
  for (const glm::dvec3& x : solver.download().x) {
    ASSERT_TRUE(glm::all(glm::greaterThanEqual(x, d.wall_min - 1e-6)) && glm::all(glm::lessThanEqual(x, d.wall_max + 1e-6)))
        << "a particle left the tank";
  }
}

INSTANTIATE_TEST_SUITE_P(Methods, RestTest, ::testing::ValuesIn(kBounds),
                         [](const auto& info) { return std::string(info.param.method); });

}  // namespace
}  // namespace pbflow
