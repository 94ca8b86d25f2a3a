#include "bench/scaling.hpp"

#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "bench/common.hpp"
#include "gpu/gpu_solver.hpp"
#include "gpu/make_solver.hpp"
#include "gpu/memory_estimate.hpp"
#include "scene/derive.hpp"
#include "scene/parse.hpp"
#include "scene/scene.hpp"
#include "scene/seeding.hpp"
#include "sim/settle.hpp"
#include "vk/context.hpp"

namespace pbflow::bench {

namespace fs = std::filesystem;

const std::vector<std::string>& scaling_columns() {
  static const std::vector<std::string> columns = [] {
    std::vector<std::string> c = {"device",  "scene",   "method", "iterations", "particles", "spacing",
                                  "steps",   "step_ms", "wall_step_ms", "particle_steps_per_s",
                                  "device_bytes_per_particle"};
    for (const char* pass : kPassGroupNames) c.push_back(std::string(pass) + "_ms");
    for (const char* k : {"fit_intercept_ms", "fit_ms_per_particle", "loglog_slope"}) c.push_back(k);
    return c;
  }();
  return columns;
}

namespace {

struct Measured {
  std::vector<std::string> cells;  // up to the pass groups; the fit is appended at the end
  std::string device, setting;     // for the printed table: "llvmpipe ...", "ldc@1"
  double particles = 0, step_ms = 0, wall_s = 0, bytes_per_particle = 0;
};

// Weighted least squares y = a + b x; the log-log slope is the same on log x, log y.
struct Line {
  double a = 0, b = 0;
};
Line fit(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& w) {
  double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < x.size(); ++i)
    sw += w[i], sx += w[i] * x[i], sy += w[i] * y[i], sxx += w[i] * x[i] * x[i], sxy += w[i] * x[i] * y[i];
  const double det = sw * sxx - sx * sx;
  if (x.size() < 2 || det == 0) return {sw > 0 ? sy / sw : 0, 0};
  const double b = (sw * sxy - sx * sy) / det;
  return {(sy - b * sx) / sw, b};
}

Measured measure(const ScalingOptions& o, const Scene& base, const vk::Context* ctx, int count) {
  std::vector<std::string> overrides = {"particle_spacing=" + number(spacing_for(base, count))};
  if (!o.method.empty()) overrides.push_back("solver.method=" + o.method);
  if (o.iterations > 0) overrides.push_back("solver.iterations=" + std::to_string(o.iterations));
  const Scene scene = load_scene(o.scene, overrides);
  const Derived d = derive(scene);
  check_fits(scene, ctx);  // InputError: this count does not fit; before its particles are made
  const auto x0 = initial_particles(scene);
  const MemoryNeed need = memory_need(d, double(x0.size()), ctx ? &ctx->info() : nullptr);

  std::unique_ptr<Solver> solver = make_solver(ctx, d, x0);
  relax_start(*solver);  // as `pbflow run` starts
  if (auto* gpu = dynamic_cast<GpuSolver*>(solver.get())) gpu->set_profiling(true);
  const int substeps = scene.solver.substeps;
  const int frames = std::max(1, int(std::lround(o.seconds * scene.fps)));
  solver->advance(0);
  solver->advance(substeps);  // warm-up: pipelines, caches, first allocations
  double step_ms = 0;
  std::array<double, kStepGroups> pass_ms{};
  const auto start = std::chrono::steady_clock::now();
  for (int f = 0; f < frames; ++f) {
    const FrameStats s = solver->advance(substeps);
    step_ms += s.step_ms / frames;
    for (size_t p = 0; p < kStepGroups; ++p) pass_ms[p] += s.pass_ms[p] / frames;
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const int steps = frames * substeps;
  const double n = double(x0.size());
  Measured m;
  m.particles = n;
  m.step_ms = step_ms;
  m.wall_s = wall_s;
  m.bytes_per_particle = double(ctx ? need.device : need.host) / n;
  m.device = solver->device_name();
  m.setting = std::string(method_name(scene.solver.method)) + "@" + std::to_string(scene.solver.iterations);
  m.cells = {m.device,
             o.scene,
             method_name(scene.solver.method),
             std::to_string(scene.solver.iterations),
             std::to_string(x0.size()),
             number(scene.particle_spacing),
             std::to_string(steps),
             number(step_ms),
             number(1e3 * wall_s / steps),
             number(n / (step_ms * 1e-3)),
             number(m.bytes_per_particle)};
  for (double p : pass_ms) m.cells.push_back(number(p));
  return m;
}

// Each count in turn, until one would pass the budget or does not fit.
std::vector<Measured> measure_counts(const ScalingOptions& o, const std::vector<int>& counts, const Scene& base,
                                     const vk::Context* ctx) {
  const bool tty = isatty(STDERR_FILENO);
  const auto start = std::chrono::steady_clock::now();
  std::vector<Measured> rows;
  for (int count : counts) {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!rows.empty()) {  // cost grows with the particles: the next count takes about this long
      const double predicted = rows.back().wall_s * 3 * count / rows.back().particles;  // set-up and warm-up too
      if (elapsed + predicted > 60 * o.budget_minutes) {
        std::fprintf(stderr, "%sstopped before %d particles: about %.0f s more would pass --budget-minutes %g\n",
                     tty ? "\n" : "", count, predicted, o.budget_minutes);
        break;
      }
    }
    try {
      rows.push_back(measure(o, base, ctx, count));
    } catch (const InputError& e) {  // the device (or host) cannot hold this count: the model ends here
      std::fprintf(stderr, "%sstopped at %d particles: %s\n", tty ? "\n" : "", count, e.what());
      break;
    }
    const Measured& m = rows.back();
    std::fprintf(stderr, "%s[%zu/%zu] %.0f particles: %.2f ms per step%s", tty ? "\r" : "", rows.size(), counts.size(),
                 m.particles, m.step_ms, tty ? "   " : "\n");
  }
  if (tty) std::fprintf(stderr, "\n");
  return rows;
}

}  // namespace

int run_scaling(const ScalingOptions& o) {
  std::vector<int> counts = o.counts;
  if (counts.empty()) {
    for (int n = 10000; n < 4000000; n *= 2) counts.push_back(n);
    counts.push_back(4000000);
  }
  for (size_t i = 0; i < counts.size(); ++i) {
    if (counts[i] < 100 || counts[i] > 100000000) throw InputError("--counts: particle counts must be from 100 to 100000000");
    if (i && counts[i] <= counts[i - 1]) throw InputError("--counts: for --scaling, in increasing order");
  }
  if (!(o.seconds > 0 && o.seconds <= 60)) throw InputError("--seconds: simulated seconds per count, in (0, 60]");
  if (!(o.budget_minutes > 0)) throw InputError("--budget-minutes must be positive");
  const Scene base = load_scene(o.scene);  // a wrong name fails before any run

  std::unique_ptr<vk::Context> ctx = make_context(o.device, false);
  std::error_code error;
  fs::create_directories(o.out, error);
  if (error) throw InputError("cannot create --out " + o.out + ": " + error.message());
  std::vector<Measured> rows = measure_counts(o, counts, base, ctx.get());
  if (rows.empty()) throw InputError("--scaling: no particle count could run (see above)");

  // Cost against particles: the straight line, weighted by 1/ms^2 so that every count's
  // relative error counts alike over three decades (unweighted, the largest counts alone
  // set it and its intercept went negative), and the log-log slope over the larger half
  // of the counts (the small ones carry the fixed cost of a step's dispatches).
  std::vector<double> n, ms, relative, log_n, log_ms;
  for (const Measured& m : rows)
    n.push_back(m.particles), ms.push_back(m.step_ms), relative.push_back(1.0 / std::max(m.step_ms * m.step_ms, 1e-12));
  const Line line = fit(n, ms, relative);
  for (size_t i = rows.size() / 2; i < rows.size(); ++i)
    log_n.push_back(std::log(n[i])), log_ms.push_back(std::log(std::max(ms[i], 1e-9)));
  const double slope = log_n.size() >= 2 ? fit(log_n, log_ms, std::vector<double>(log_n.size(), 1.0)).b : NAN;

  OutputFile csv(fs::path(o.out) / "scaling.csv");
  csv.write(join(scaling_columns()) + "\n");
  std::printf("%s, %s %s\n%12s %12s %14s %14s\n", rows[0].device.c_str(), o.scene.c_str(), rows[0].setting.c_str(),
              "particles", "ms/step", "M p-steps/s", "bytes/particle");
  for (Measured& m : rows) {
    for (double v : {line.a, line.b, slope}) m.cells.push_back(number(v));
    csv.write(join(m.cells) + "\n");
    std::printf("%12.0f %12.3f %14.3f %14.1f\n", m.particles, m.step_ms, m.particles / (m.step_ms * 1e-3) * 1e-6,
                m.bytes_per_particle);
  }
  csv.close();  // complete before the chart script reads it
  std::printf("fit: %.4g ms + %.4g ms per million particles; log-log slope over the larger half %.3f (1: linear)\n",
              line.a, line.b * 1e6, slope);
  std::cout << "scaling: " << (fs::path(o.out) / "scaling.csv").string() << "\n";
  if (o.charts) draw_charts(o.out);
  return 0;
}

}  // namespace pbflow::bench
