// Adaptive iterations: the GPU decides on its own (indirect dispatch) how many constraint
// iterations a step runs, the same as the reference decides, and a tighter target costs
// more iterations and compresses less.
#include "gpu/gpu_solver.hpp"
#include "sim/reference_solver.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

class AdaptiveTest : public test::GpuTest {
 protected:
  static Scene scene(double target, int max_iterations = 15) {
    return load_scene("dam_break", {"particle_spacing=0.04", "solver.iterations=1",
                                    "solver.max_iterations=" + std::to_string(max_iterations),
                                    "solver.target_compression=" + std::to_string(target)});
  }
};

TEST_F(AdaptiveTest, GpuRunsTheIterationsTheReferenceRuns) {
  Scene s = scene(0.002);
  Derived d = derive(s);
  auto x0 = initial_particles(s);
  GpuSolver gpu(test::gpu(), d, x0);
  ReferenceSolver ref(d, x0);
  for (int frame = 0; frame < 6; ++frame) {
    FrameStats g = gpu.advance(2), r = ref.advance(2);
    std::printf("[ adaptive ] frame %d: iterations per step gpu %.1f, reference %.1f\n", frame, g.iterations,
                r.iterations);
    EXPECT_EQ(g.iterations, r.iterations) << "frame " << frame;
    EXPECT_GE(g.iterations, 1.0);
    EXPECT_LE(g.iterations, 15.0);
  }
  test::ErrorReport e = test::compare(gpu.download().x, ref.state.x, "adaptive positions after 12 steps");
  EXPECT_LT(e.max_abs, 1e-4);  // metres
}

using AdaptiveTestSlow = AdaptiveTest;  // the `slow` label (tests/CMakeLists.txt)
TEST_F(AdaptiveTestSlow, TighterTargetsCostMoreIterationsAndCompressLess) {
  double last_iterations = 0, last_compression = 1e9;
  for (double target : {0.02, 0.005, 0.001}) {
    Scene s = scene(target, 41);
    GpuSolver gpu(test::gpu(), derive(s), initial_particles(s));
    double iterations = 0, compression = 0;
    for (int frame = 0; frame < 20; ++frame) {
      FrameStats f = gpu.advance(2);
      iterations += f.iterations / 20;
      compression += f.mean_compression / 20;
    }
    std::printf("[ adaptive ] target %.3f: %.2f iterations per step, mean compression %.4f\n", target, iterations,
                compression);
    EXPECT_GT(iterations, last_iterations) << "target " << target;
    EXPECT_LT(compression, last_compression) << "target " << target;
    last_iterations = iterations;
    last_compression = compression;
  }
  EXPECT_GT(last_iterations, 2.0) << "the tightest target never made the solver iterate more";
}

}  // namespace
}  // namespace pbflow
