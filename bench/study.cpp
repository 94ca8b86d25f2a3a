#include "bench/study.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "bench/common.hpp"
#include "gpu/gpu_solver.hpp"
#include "gpu/make_solver.hpp"
#include "scene/derive.hpp"
#include "scene/parse.hpp"
#include "scene/scene.hpp"
#include "scene/seeding.hpp"
#include "sim/settle.hpp"
#include "vk/context.hpp"

namespace pbflow::bench {

namespace fs = std::filesystem;

const std::vector<std::string>& run_columns() {
  static const std::vector<std::string> columns = [] {
    std::vector<std::string> c = {"run",        "device",      "scene",        "particles",    "method",
                                  "iterations", "target_compression", "ldc_strength", "ldc_k", "substeps", "simulated_s",
                                  "step_ms_mean", "step_ms_median", "step_ms_max", "iterations_used"};
    for (const char* pass : kPassGroupNames) c.push_back(std::string(pass) + "_ms");
    for (const char* k : {"particle_steps_per_s", "mean_compression_avg", "max_compression_avg",
                          "max_compression_peak", "final_mean_compression", "settle_mm", "kinetic_energy_final",
                          "energy_gain", "energy_rise", "diverged", "class"})
      c.push_back(k);
    return c;
  }();
  return columns;
}

namespace {

struct Run {
  std::string scene, method;
  int particles_wanted, iterations;
  double ldc_strength;  // 0: the scene's
  double target;  // adaptive when > 0: iterations from `iterations` up to kMaxAdaptive
  int substeps;   // 0: the scene's
};

constexpr int kMaxAdaptive = 41;   // 1 + 20 pairs
constexpr double kBlownUp = 9.0;   // max compression (rho = 10 rho0) at which a run counts as diverged
constexpr double kCompressed = 0.02;  // time-averaged mean compression above which a run counts as compressed
constexpr double kGainsEnergy = 0.01;  // energy gain (of PE_0) above which a run is unsound (docs/design.md)

struct Outcome {
  std::vector<std::string> cells;  // runs.csv row
  std::string series;              // series.csv rows
};

double mean_height(const ParticleFrame& f) {
  double sum = 0;
  for (const glm::vec4& x : f.x) sum += x.y;
  return f.x.empty() ? 0 : sum / double(f.x.size());
}

// The scene of run `r`, `seconds` long.
Scene scene_of(const Run& r, double seconds) {
  Scene base = load_scene(r.scene);
  const double spacing = spacing_for(base, r.particles_wanted);
  const int frames = std::max(2, int(std::lround(seconds * base.fps)) + 1);
  std::vector<std::string> overrides = {"particle_spacing=" + number(spacing), "solver.method=\"" + r.method + "\"",
                                        "solver.iterations=" + std::to_string(r.iterations),
                                        "frames=" + std::to_string(frames)};
  if (r.ldc_strength > 0) overrides.push_back("solver.ldc_strength=" + number(r.ldc_strength));
  if (r.substeps > 0) overrides.push_back("solver.substeps=" + std::to_string(r.substeps));
  if (r.target > 0) {
    overrides.push_back("solver.target_compression=" + number(r.target));
    overrides.push_back("solver.max_iterations=" + std::to_string(kMaxAdaptive));
  }
  return load_scene(r.scene, overrides);
}

// A frame's row of series.csv.
std::string series_row(int run, int frame, double fps, const FrameStats& s) {
  return std::to_string(run) + "," + std::to_string(frame) + "," + number(frame / fps) + "," + number(s.mean_compression) +
         "," + number(s.max_compression) + "," + number(s.kinetic_energy) + "," + number(s.potential_energy) + "\n";
}

// A run's measured frames (every frame after frame 0), summed.
struct Tally {
  double sum_mean = 0, sum_max = 0, peak = 0, step_sum = 0, step_max = 0, iteration_sum = 0;
  std::vector<double> step_ms;  // for the median: on a shared machine a neighbour's burst moves the mean
  std::array<double, kStepGroups> pass_sum{};
  int measured = 0;

  void add(const FrameStats& s, int frame) {
    sum_mean += s.mean_compression;
    sum_max += s.max_compression;
    peak = std::max(peak, s.max_compression);
    step_sum += s.step_ms;
    step_ms.push_back(s.step_ms);
    step_max = std::max(step_max, s.step_ms);
    iteration_sum += s.iterations;
    for (size_t p = 0; p < kStepGroups; ++p) pass_sum[p] += s.pass_ms[p];
    measured = frame;
  }
  double median_step() {
    if (step_ms.empty()) return 0.0;
    std::nth_element(step_ms.begin(), step_ms.begin() + step_ms.size() / 2, step_ms.end());
    return step_ms[step_ms.size() / 2];
  }
};

Outcome simulate(const Run& r, int index, double seconds, const vk::Context* ctx) {
  const Scene scene = scene_of(r, seconds);
  Derived d = derive(scene);
  auto x0 = initial_particles(scene);
  std::unique_ptr<Solver> solver = make_solver(ctx, d, x0);
  relax_start(*solver);  // as `pbflow run` starts
  if (scene.settle) settle(*solver, d);  // as `pbflow run` does: the tank starts in its equilibrium
  if (auto* gpu = dynamic_cast<GpuSolver*>(solver.get())) gpu->set_profiling(true);

  const double height0 = mean_height(solver->read_frame());
  std::ostringstream series;
  Tally t;
  EnergyGain gain;
  FrameStats s;
  bool diverged = false;
  for (int frame = 0; frame < scene.frames; ++frame) {
    s = solver->advance(frame == 0 ? 0 : scene.solver.substeps);
    series << series_row(index, frame, scene.fps, s);
    gain.add(s);
    // A blown-up run (particles piled at 10x rest density, or NaN) only gets slower as
    // its neighbour lists grow: it is recorded as diverged and stopped.
    diverged = diverged || s.divergence.any() || !std::isfinite(s.kinetic_energy) || !(s.max_compression < kBlownUp);
    if (frame == 0) continue;
    t.add(s, frame);
    if (diverged) break;
  }
  const int measured = t.measured;
  const double step_mean = t.step_sum / measured;
  std::vector<std::string> row = {std::to_string(index),
                                  solver->device_name(),
                                  r.scene,
                                  std::to_string(x0.size()),
                                  r.method,
                                  std::to_string(r.iterations),
                                  number(r.target),
                                  number(r.method == "ldc" ? scene.solver.ldc_strength : 0.0),
                                  number(r.method == "ldc" ? d.ldc_k : 0.0),
                                  std::to_string(scene.solver.substeps),
                                  number(measured / scene.fps),
                                  number(step_mean),
                                  number(t.median_step()),
                                  number(t.step_max),
                                  number(t.iteration_sum / measured)};
  for (double p : t.pass_sum) row.push_back(number(p / measured));
  row.push_back(number(double(x0.size()) / (step_mean * 1e-3)));
  row.push_back(number(t.sum_mean / measured));
  row.push_back(number(t.sum_max / measured));
  row.push_back(number(t.peak));
  row.push_back(number(s.mean_compression));
  row.push_back(number(1000.0 * (height0 - mean_height(solver->read_frame()))));
  row.push_back(number(s.kinetic_energy));
  row.push_back(number(gain.largest()));
  row.push_back(number(gain.largest_rise()));
  row.push_back(diverged ? "1" : "0");
  row.push_back(diverged                          ? "diverged"
                : gain.largest() > kGainsEnergy    ? "gains energy"
                : t.sum_mean / measured > kCompressed ? "compressed"
                                                    : "stable");
  return {row, series.str()};
}

// The study's runs from its options (each list's default where it is empty), each option checked.
std::vector<Run> plan_runs(const StudyOptions& options, double& seconds) {
  StudyOptions o = options;
  if (o.stability) {  // the map's defaults, each unless given
    if (o.scenes.empty()) o.scenes = {"dam_break", "drop"};
    if (o.counts.empty()) o.counts = {4000};
    if (o.iterations.empty()) o.iterations = {1, 2, 4};
    if (o.substeps.empty()) o.substeps = {1, 2, 4};
    if (o.ldc_strength.empty()) o.ldc_strength = {0.25, 0.5, 0.9};
    if (o.seconds <= 0) o.seconds = 1.0;
  }
  std::vector<int> counts = o.counts, iterations = o.iterations;
  if (counts.empty()) counts = o.quick ? std::vector<int>{4000} : std::vector<int>{10000, 40000, 160000};
  if (iterations.empty()) iterations = o.quick ? std::vector<int>{1, 2, 3} : std::vector<int>{1, 2, 3, 4, 6, 8};
  if (!o.targets.empty() && o.iterations.empty()) iterations.clear();  // --targets alone: adaptive runs only
  seconds = o.seconds > 0 ? o.seconds : o.quick ? 1.0 : 2.0;
  for (int n : o.substeps)
    if (n < 1 || n > 1000) throw InputError("--substeps: from 1 to 1000");
  const std::vector<int> substeps = o.substeps.empty() ? std::vector<int>{0} : o.substeps;
  for (int c : counts)
    if (c < 100 || c > 100000000) throw InputError("--counts: particle counts must be from 100 to 100000000");
  for (int k : iterations)
    if (k < 1 || k > 1000) throw InputError("--iterations: from 1 to 1000");
  if (!(seconds > 0 && seconds <= 3600)) throw InputError("--seconds must be in (0, 3600]");

  std::vector<std::string> scenes = o.scenes.empty() ? std::vector<std::string>{"dam_break", "hydrostatic"} : o.scenes;
  for (const std::string& s : scenes) load_scene(s);  // a wrong name fails before any run
  for (double k : o.ldc_strength)
    if (!(k > 0 && k < 1)) throw InputError("--ldc-strength: fractions of the step's stability limit, in (0, 1)");
  std::vector<double> ks = o.ldc_strength.empty() ? std::vector<double>{0.0} : o.ldc_strength;
  std::vector<Run> runs;
  for (double t : o.targets)
    if (!(t > 0 && t < 1)) throw InputError("--targets: mean compressions in (0, 1), e.g. 0.01,0.001");
  for (const std::string& scene : scenes)
    for (int count : counts)
      for (int sub : substeps) {
        for (int k : iterations) {
          runs.push_back({scene, "pbf", count, k, 0.0, 0.0, sub});
          for (double K : ks) runs.push_back({scene, "ldc", count, k, K, 0.0, sub});
        }
        for (double t : o.targets) {  // adaptive: from one iteration until the target
          runs.push_back({scene, "pbf", count, 1, 0.0, t, sub});
          for (double K : ks) runs.push_back({scene, "ldc", count, 1, K, t, sub});
        }
      }
  return runs;
}

}  // namespace

int run_study(const StudyOptions& o) {
  double seconds = 0;
  const std::vector<Run> runs = plan_runs(o, seconds);
  // One device for the sitting, as a user's process has: NVIDIA's driver refused a 30th
  // instance made and destroyed in one process (H200, driver 580), and each costs a start.
  std::unique_ptr<vk::Context> ctx = make_context(o.device, false);
  for (const Run& r : runs) check_fits(scene_of(r, seconds), ctx.get());  // before any particle is made
  std::error_code error;
  fs::create_directories(o.out, error);
  if (error) throw InputError("cannot create --out " + o.out + ": " + error.message());
  OutputFile runs_csv(fs::path(o.out) / "runs.csv"), series_csv(fs::path(o.out) / "series.csv");
  runs_csv.write(join(run_columns()) + "\n");
  series_csv.write("run,frame,time,mean_compression,max_compression,kinetic_energy,potential_energy\n");
  const bool tty = isatty(STDERR_FILENO);
  auto start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < runs.size(); ++i) {
    const Run& r = runs[i];
    Outcome out = simulate(r, int(i), seconds, ctx.get());
    runs_csv.write(join(out.cells) + "\n");
    series_csv.write(out.series);
    double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double left = elapsed / double(i + 1) * double(runs.size() - i - 1);
    std::fprintf(stderr, "%s[%zu/%zu] %s %s particles %s@%d  %.0f s, about %.0f s left%s", tty ? "\r" : "", i + 1,
                 runs.size(), r.scene.c_str(), out.cells[3].c_str(), r.method.c_str(), r.iterations, elapsed, left,
                 tty ? "   " : "\n");
  }
  if (tty) std::fprintf(stderr, "\n");
  runs_csv.close();
  series_csv.close();
  std::cout << "runs: " << (fs::path(o.out) / "runs.csv").string()
            << "\nseries: " << (fs::path(o.out) / "series.csv").string() << "\n";
  if (o.charts) draw_charts(o.out);
  return 0;
}

}  // namespace pbflow::bench
