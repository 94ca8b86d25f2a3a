// The memory estimate is what a run holds: the GPU solver allocates exactly its buffer plan,
// and the estimate that refuses a run too large sums that plan.
#include "gpu/buffer_plan.hpp"
#include "gpu/gpu_solver.hpp"
#include "gpu/memory_estimate.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

struct Case {
  const char* name;
  const char* scene;
  std::vector<std::string> params;
  bool lists = true;
};

class MemoryTest : public test::GpuTest, public ::testing::WithParamInterface<Case> {};

TEST_P(MemoryTest, TheSolverAllocatesItsPlanAndTheEstimateCoversIt) {
  const Scene s = load_scene(GetParam().scene, GetParam().params);
  Derived d = derive(s);
  if (!GetParam().lists) d.neighbour_capacity = 0;
  const auto x0 = initial_particles(s);
  const uint64_t before = test::gpu().buffer_bytes();
  uint64_t held = 0;
  {
    GpuSolver solver(test::gpu(), d, x0);
    solver.advance(1);
    held = test::gpu().buffer_bytes() - before;
  }
  EXPECT_EQ(test::gpu().buffer_bytes(), before) << "every buffer is freed with the solver";
  const uint64_t planned = plan_buffers(d, x0.size()).total();
  std::printf("[ memory ] %zu particles: the solver holds %llu bytes, its plan %llu\n", x0.size(),
              (unsigned long long)held, (unsigned long long)planned);
  EXPECT_EQ(held, planned);
  EXPECT_GE(memory_need(d, double(x0.size()), &test::gpu().info(), 0).device, held);
}

// The buffers each option adds: none, vorticity's omega, smoothing's spare, the adaptive
// iterations' words, obstacles, and no neighbour lists at all.
INSTANTIATE_TEST_SUITE_P(
    Options, MemoryTest,
    ::testing::Values(Case{"defaults", "dam_break", {"particle_spacing=0.04"}},
                      Case{"vorticity_smoothing", "dam_break",
                           {"particle_spacing=0.04", "solver.vorticity=0.01", "solver.lambda_smoothing=2"}},
                      Case{"adaptive", "dam_break",
                           {"particle_spacing=0.04", "solver.target_compression=0.01", "solver.max_iterations=5"}},
                      Case{"obstacles_no_lists", "dam_obstacle", {"particle_spacing=0.04"}, false}),
    [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace pbflow
