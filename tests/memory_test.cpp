// The memory estimate is what a run holds: the GPU solver allocates exactly its buffer plan,
// and the estimate that refuses a run too large sums that plan.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "gpu/buffer_plan.hpp"
#include "gpu/gpu_solver.hpp"
#include "gpu/memory_estimate.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

namespace fs = std::filesystem;

struct Case {
  const char* name;
  const char* scene;
  std::vector<std::string> params;
  bool lists = true;
  FrameOutputs outputs = {};
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
    solver.set_outputs(GetParam().outputs);
    solver.advance(1);
    held = test::gpu().buffer_bytes() - before;
    if (GetParam().outputs != FrameOutputs{}) {  // and an output switched off holds nothing
      solver.set_outputs({});
      EXPECT_EQ(test::gpu().buffer_bytes() - before, plan_buffers(d, x0.size()).total());
    }
  }
  EXPECT_EQ(test::gpu().buffer_bytes(), before) << "every buffer is freed with the solver";
  const uint64_t planned = plan_buffers(d, x0.size(), GetParam().outputs).total();
  std::printf("[ memory ] %zu particles: the solver holds %llu bytes, its plan %llu\n", x0.size(),
              (unsigned long long)held, (unsigned long long)planned);
  EXPECT_EQ(held, planned);
  EXPECT_GE(memory_need(d, double(x0.size()), &test::gpu().info(), {}, GetParam().outputs).device, held);
}

// The buffers each option adds: none, vorticity's curl, smoothing's spare, the adaptive
// iterations' words, obstacles, no neighbour lists at all, and every output a frame makes.
INSTANTIATE_TEST_SUITE_P(
    Options, MemoryTest,
    ::testing::Values(Case{"defaults", "dam_break", {"particle_spacing=0.04"}},
                      Case{"vorticity_smoothing", "dam_break",
                           {"particle_spacing=0.04", "solver.vorticity=0.01", "solver.lambda_smoothing=2"}},
                      Case{"adaptive", "dam_break",
                           {"particle_spacing=0.04", "solver.target_compression=0.01", "solver.max_iterations=5"}},
                      Case{"obstacles_no_lists", "dam_obstacle", {"particle_spacing=0.04"}, false},
                      Case{"every_output",
                           "dam_break",
                           {"particle_spacing=0.04", "white_water.enabled=true", "white_water.max_particles=5000"},
                           true,
                           {.surface = true, .white_water = true}}),
    [](const auto& info) { return std::string(info.param.name); });

// A run's peak resident memory (its own, from wait4) in bytes, and its exit status.
std::pair<uint64_t, int> peak_of_run(std::vector<std::string> args) {
  args.insert(args.begin(), PBFLOW_BINARY);
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    execv(PBFLOW_BINARY, argv.data());
    _exit(127);
  }
  int status = 0;
  rusage usage{};
  wait4(pid, &status, 0, &usage);
  return {uint64_t(usage.ru_maxrss) * 1024, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

// The estimate that refuses a run too large for the machine is never under what the run
// really holds at its peak: the reference solver, lavapipe's solver, and the renderer.
TEST(MemoryEstimate, IsNeverUnderARunsMeasuredPeak) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "under AddressSanitizer: its shadow memory and quarantine are not the run's";
#endif
  const fs::path dir = test::fresh_dir("memory_peak");
  for (const std::vector<std::string>& options :
       {std::vector<std::string>{"--device", "cpu", "--no-render"}, {"--device", "cpu", "--width", "640", "--height", "360"},
        {"--no-render"}, {"--width", "1280", "--height", "720"}}) {
    std::vector<std::string> args = {"run", "dam_break", "--param", "particle_spacing=0.03", "--frames", "20",
                                     "--quiet", "--out", dir.string()};
    args.insert(args.end(), options.begin(), options.end());
    const auto [peak, status] = peak_of_run(args);
    ASSERT_EQ(status, 0) << options[0];
    std::ifstream in(dir / "run.json");
    const nlohmann::json m = nlohmann::json::parse(in);
    const uint64_t estimate = m["memory_estimate"]["host_bytes"].get<uint64_t>();
    std::printf("[ memory ] %s %s: peak %.1f MiB, estimate %.1f MiB\n", options[0].c_str(), options.back().c_str(),
                peak / 1048576.0, estimate / 1048576.0);
    EXPECT_GE(estimate, peak) << options[0] << " " << options.back();
    EXPECT_LT(estimate, 4 * peak + (64u << 20)) << "an estimate this loose refuses runs that fit";
  }
}

}  // namespace
}  // namespace pbflow
