// Throughput of the GPU solver and the C++ reference on dam_break at a given particle
// count: particle-steps per second from the mean step time (GPU timestamps; wall time
// for the reference). Prints one markdown table row per run.
//
//   build/bench/pbflow_throughput PARTICLES METHOD ITERATIONS DEVICE [FRAMES]
//   e.g. build/bench/pbflow_throughput 100000 ldc 1 auto 10
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "gpu/make_solver.hpp"
#include "scene/derive.hpp"
#include "scene/parse.hpp"
#include "scene/scene.hpp"
#include "scene/seeding.hpp"
#include "sim/settle.hpp"
#include "vk/context.hpp"

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: %s PARTICLES pbf|ldc ITERATIONS auto|cpu|INDEX [FRAMES]\n", argv[0]);
    return 2;
  }
  const double wanted = std::atof(argv[1]);
  const std::string method = argv[2], iterations = argv[3], device = argv[4];
  const int frames = argc > 5 ? std::atoi(argv[5]) : 10;
  try {
    // dam_break's block is 0.4 x 0.8 x 0.4 m: choose the spacing that fills it with ~PARTICLES.
    const double spacing = std::cbrt(0.4 * 0.8 * 0.4 / wanted);
    pbflow::Scene scene = pbflow::load_scene(
        "dam_break", {"particle_spacing=" + std::to_string(spacing), "solver.method=\"" + method + "\"",
                      "solver.iterations=" + iterations});
    pbflow::Derived d = pbflow::derive(scene);
    auto x0 = pbflow::initial_particles(scene);
    std::unique_ptr<pbflow::vk::Context> ctx = pbflow::make_context(device, false);
    auto solver = pbflow::make_solver(ctx.get(), d, x0);
    pbflow::relax_start(*solver);  // as `pbflow run` starts
    solver->advance(scene.solver.substeps);  // warm-up: pipelines, caches, first sort
    double ms = 0;
    for (int f = 0; f < frames; ++f) ms += solver->advance(scene.solver.substeps).step_ms;
    ms /= frames;
    std::printf("| %s | %zu | %s | %s | %d | %.2f | %.3g |\n", solver->device_name().c_str(), x0.size(),
                method.c_str(), iterations.c_str(), frames * scene.solver.substeps, ms, x0.size() / (ms * 1e-3));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pbflow_throughput: %s\n", e.what());
    return 1;
  }
}
