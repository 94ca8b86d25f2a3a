#include "app/run.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>

#include "app/interrupt.hpp"
#include "common/pause_point.hpp"
#include "capture/frame_capture.hpp"
#include "capture/particle_export.hpp"
#include "gpu/make_solver.hpp"
#include "gpu/memory_estimate.hpp"
#include "io/run_directory.hpp"
#include "io/stats_csv.hpp"
#include "scene/derive.hpp"
#include "sim/frame_plan.hpp"
#include "scene/parse.hpp"
#include "scene/scene.hpp"
#include "scene/seeding.hpp"
#include "sim/settle.hpp"
#include "vk/context.hpp"

namespace pbflow {

std::vector<std::string> scene_overrides(const RunOptions& o) {
  std::vector<std::string> all = o.params;
  if (!o.method.empty()) all.push_back("solver.method=\"" + o.method + "\"");
  if (o.iterations) all.push_back("solver.iterations=" + std::to_string(o.iterations));
  if (o.frames) all.push_back("frames=" + std::to_string(o.frames));
  return all;
}

std::unique_ptr<capture::FrameCapture> make_frame_capture(const RunOptions& o, const Scene& scene,
                                                          const std::vector<const Solver*>& solvers,
                                                          const vk::Context* vk) {
  if (o.width < 16 || o.height < 16 || o.width > 16384 || o.height > 16384)
    throw InputError("--width and --height must be between 16 and 16384 pixels");
  capture::CaptureOptions c;
  c.view.width = o.width;
  c.view.height = o.height;
  c.view.style = capture::parse_style(o.style);
  if (o.fluid_resolution != "half" && o.fluid_resolution != "full")
    throw InputError("--fluid-resolution must be half or full, not '" + o.fluid_resolution + "'");
  c.view.surface_divisor = o.fluid_resolution == "half" ? 2 : 1;
  c.view.camera = scene.camera;
  c.view.domain = scene.domain;
  c.view.obstacles = scene.obstacles;
  c.view.particle_radius = 0.5 * scene.particle_spacing;
  c.view.rest_density = scene.solver.rest_density;
  // Red in the speed style: the speed of a fall through the domain's height.
  c.view.speed_scale = std::max(fall_speed(scene), 0.1);
  c.video = o.video;
  c.fps = scene.fps;
  c.allow_shared = !o.readback;
  c.debug = o.validate;
  if (vk) c.device_uuid = vk->device_uuid();
  return std::make_unique<capture::FrameCapture>(c, solvers, vk);
}

FrameOutputs run_outputs(const RunOptions& o) {
  const capture::Style style = capture::parse_style(o.style);
  return capture::frame_outputs(o.render ? &style : nullptr,
                                capture::parse_export_format(o.export_format) != capture::ExportFormat::None);
}

MemoryNeed check_run_memory(const RunOptions& o, const Scene& scene, const Derived& d, const vk::DeviceInfo* device,
                            size_t solvers) {
  const bool full_surface = o.fluid_resolution == "full";
  const double pixels = o.render ? double(o.width) * o.height * double(solvers) : 0.0, start = particle_estimate(scene);
  MemoryNeed need = memory_need(d, start, device, {pixels, full_surface}, run_outputs(o));
  need.device *= solvers;  // each solver's buffers and host arrays, once each
  need.host = need.picture + (need.host - need.picture) * solvers;
  MemoryAdvice advice;
  if (full_surface) advice.picture += ", or leave out --fluid-resolution full";
  if (const size_t room = d.flows() ? d.capacity_for(size_t(start)) : 0; double(room) > 1.5 * start)
    advice.particles = "lower capacity (room for " + std::to_string(room) +
                       " particles, the start's and what the emitters bring) or " + advice.particles;
  check_memory(need, device, advice);
  return need;
}

namespace {

// The run's progress on stderr: on a terminal one line redrawn in place; elsewhere (a CI log,
// a pipe) a line every 10 s, so that a long run is not silent until its end. None with --quiet.
class Progress {
 public:
  Progress(int frames, bool enabled) : frames_(frames), enabled_(enabled), terminal_(isatty(STDERR_FILENO)) {}
  void update(int frame, double sim_time, double elapsed_s) {
    if (!due()) return;
    double rate = frame / std::max(elapsed_s, 1e-9);
    double left = (frames_ - 1 - frame) / std::max(rate, 1e-9);
    say("frame %d/%d  t = %.2f s  %.1f frames/s  %.0f s left", frame + 1, frames_, sim_time, rate, left);
  }
  void relaxing(int relaxation) {
    if (due()) say("relaxing the start: %d/%d", relaxation, kStartRelaxations);
  }
  void settling(int step) {
    if (due()) say("settling: step %d", step);
  }
  void done() {
    if (enabled_ && terminal_) std::fprintf(stderr, "\r%*s\r", 70, "");
  }

 private:
  static constexpr double kLogSeconds = 10;  // between lines where stderr is not a terminal
  bool due() {
    if (!enabled_) return false;
    if (terminal_) return true;
    const auto now = std::chrono::steady_clock::now();
    if (std::chrono::duration<double>(now - last_).count() < kLogSeconds) return false;
    last_ = now;
    return true;
  }
  template <typename... Args>
  void say(const char* format, Args... args) {
    char line[160];
    std::snprintf(line, sizeof line, format, args...);
    std::fprintf(stderr, terminal_ ? "\r%s   " : "pbflow: %s\n", line);
  }

  int frames_;
  bool enabled_, terminal_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// What DIR/run.json records of a run besides its files and status. "chosen": what pbflow
// picked where the scene left a key out, as the --param that would state it.
nlohmann::json describe_run(const RunOptions& o, const Scene& scene, const Derived& d, const Solver& solver) {
  const nlohmann::json stated = nlohmann::json::parse(scene.resolved);
  nlohmann::json chosen = {{"solver.lambda_smoothing", d.solver.lambda_smoothing}};
  if (!stated.contains(nlohmann::json::json_pointer("/solver/substeps")))
    chosen["solver.substeps"] = scene.solver.substeps;  // chosen_substeps
  // The keys' defaults, from the accuracy-against-cost front (host/scene/keys.cpp).
  if (!stated.contains(nlohmann::json::json_pointer("/solver/method")))
    chosen["solver.method"] = method_name(scene.solver.method);
  if (!stated.contains(nlohmann::json::json_pointer("/solver/iterations")))
    chosen["solver.iterations"] = scene.solver.iterations;
  if (!stated.contains(nlohmann::json::json_pointer("/white_water/max_particles")))
    chosen["white_water.max_particles"] = d.white_water.max_particles;
  const nlohmann::json camera = stated.value("camera", nlohmann::json::object());
  auto vec = [](const glm::dvec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); };
  if (!camera.contains("eye")) chosen["camera.eye"] = vec(scene.camera.eye);  // framing_camera
  if (!camera.contains("target")) chosen["camera.target"] = vec(scene.camera.target);
  if (!stated.contains("seed")) chosen["seed"] = scene.seed;  // the start's jitter: the run is its seed's
  if (d.flows() && !stated.contains("capacity")) chosen["capacity"] = solver.capacity();  // Derived::capacity_for
  return {{"scene_name", scene.name},
          {"scene", stated},
          {"chosen", chosen},
          {"options",
           {{"params", o.params}, {"device", o.device}, {"render", o.render}, {"style", o.style},
            {"fluid_resolution", o.fluid_resolution}, {"width", o.width}, {"height", o.height}, {"export", o.export_format}, {"validate", o.validate}}},
          {"video", o.video.empty() ? "" : std::filesystem::absolute(o.video).string()},
          {"device", solver.device_name()}};
}

// What run.json records of the machine: the memory estimate, and what the run's results are
// bit-reproducible against: the same device, driver and binary (docs/design.md, "Reproducibility").
void describe_machine(nlohmann::json& about, const MemoryNeed& need, const vk::DeviceInfo* device, const Solver& solver) {
  about["memory_estimate"] = {{"host_bytes", host_bytes(need, device)}, {"device_bytes", need.device}};
  about["reproducible_on"] = {{"device", solver.device_name()},
                              {"driver", device ? device->driver : "the C++ reference"},
                              {"pbflow", PBFLOW_VERSION}};
}

// What an interrupt leaves, in words: "frames 0-k are complete", or that none is.
std::string frames_complete(int frames) {
  return frames > 0 ? "frames 0-" + std::to_string(frames - 1) + " are complete" : "no frame was written";
}

// The video is not --out itself, nor a file in the folders a run owns there (it would be
// refused as foreign by the next run, or replaced by a frame).
void check_video_outside(const std::filesystem::path& video, const std::filesystem::path& out) {
  auto resolved = [](const std::filesystem::path& p) {
    std::error_code error;
    const std::filesystem::path r = std::filesystem::weakly_canonical(p, error);
    return error ? std::filesystem::absolute(p, error) : r;
  };
  const std::filesystem::path v = resolved(video), dir = resolved(out);
  if (v == dir) throw InputError("--video " + video.string() + " names the --out directory: name a file");
  for (const char* sub : {"frames", "particles"})
    if (v.parent_path() == dir / sub)
      throw InputError("--video " + video.string() + " lies in " + (out / sub).string() +
                       ", which the run owns: name a file elsewhere");
}

}  // namespace

namespace {

// The run's first line: scene, particles, setting (and what pbflow chose), device.
void announce(const RunOptions& o, const Scene& scene, const Derived& d, const nlohmann::json& chosen,
              const Solver& solver, const capture::FrameCapture* capture, bool white_water) {
  const bool chose_substeps = chosen.contains("solver.substeps");
  const bool chose_setting = chosen.contains("solver.method") || chosen.contains("solver.iterations");
  const bool pairs = d.solver.iterations >= 2 || d.solver.target_compression > 0;  // adaptive runs add pairs
  const std::string averages = pairs ? " (lambda averaged " + std::to_string(d.solver.lambda_smoothing) + "x)" : "";
  std::cerr << "pbflow: " << scene.name << ", " << solver.particle_count() << " particles, "
            << method_name(scene.solver.method) << " with " << scene.solver.iterations << " iteration(s)"
            << (chose_setting ? " (chosen)" : "") << averages << ", " << scene.solver.substeps << " substeps per frame"
            << (chose_substeps ? " (chosen)" : "") << ", on " << solver.device_name() << "\n";
  if (white_water)
    std::cerr << "pbflow: white water on, at most " << d.white_water.max_particles << " particles"
              << (chosen.contains("white_water.max_particles") ? " (chosen)" : "")
              << "; --param white_water.enabled=false turns it off\n";
  if (d.flows())
    std::cerr << "pbflow: " << d.emitters.size() << " emitter(s), " << d.drains.size() << " drain(s), room for "
              << solver.capacity() << " particles" << (chosen.contains("capacity") ? " (chosen)" : "") << "\n";
  if (capture && o.verbose) std::cerr << "pbflow: rendering with " << capture->description() << "\n";
}

// The start: its jittered lattice relaxed, and a tank settled where the scene asks.
void prepare_start(Solver& solver, const Scene& scene, const Derived& d, bool quiet, Progress& progress,
                   const InterruptGuard& interrupt) {
  relax_start(solver, [&](int relaxation) {
    if (relaxation == 1) pause_point("relax");
    progress.relaxing(relaxation);
    return !interrupt.signal();
  });
  progress.done();
  if (!scene.settle) return;
  SettleReport r = settle(solver, d, [&](int step) {
    progress.settling(step);
    return !interrupt.signal();
  });
  progress.done();
  if (!interrupt.signal() && (!quiet || !r.converged))
    std::cerr << "pbflow: settled into the solver's equilibrium in " << r.steps << " steps (potential energy "
              << (r.potential_drop >= 0 ? "-" : "+") << std::abs(r.potential_drop) << " J)"
              << (r.converged ? "" : "; still moving at the step limit") << "\n";
}

// What the frames add up to, for the summary and the exit status.
struct RunTotals {
  int frames = 0;  // complete
  double sum_mean = 0, worst = 0, sum_step_ms = 0, sum_white_water_ms = 0;
  EnergyGain energy;
  std::string diverged;  // the message, where the watch stopped the run
  bool paused = false;  // an emitter waited for room (said once)
};

// A frame's rows: stats.csv's and, where the scene's solids move, solids.csv's; bodies.csv's
// where it has bodies.
struct FrameRows {
  StatsCsv stats;
  std::unique_ptr<SolidsCsv> solids;
  std::unique_ptr<BodiesCsv> bodies;
};

// The frames: each simulated, its files written, then its rows (a row stands for a frame
// whole on disk). Stops at a divergence (nothing of that frame written) or an interrupt.
RunTotals simulate_frames(const Scene& scene, const Derived& d, Solver& solver, capture::FrameCapture* capture,
                          capture::ExportFormat export_format, RunDirectory& dir, FrameRows& rows, Progress& progress,
                          const InterruptGuard& interrupt, const std::function<double()>& wall) {
  RunTotals totals;
  int& frame = totals.frames;
  for (; frame < scene.frames && !interrupt.signal(); ++frame) {
    FrameStats s = solver.advance(frame == 0 ? 0 : scene.solver.substeps);
    double t = frame / scene.fps;
    if (s.divergence.any()) {
      long step = long(frame - 1) * scene.solver.substeps + s.divergence.first_step + 1;
      std::ostringstream m;
      m << "the simulation diverged at step " << step << " (t = " << step * d.dt << " s, frame " << frame
        << "): " << s.divergence.describe(d.speed_limit) << "; " << frames_complete(frame) << "; "
        << divergence_advice(scene, d);
      totals.diverged = m.str();
      break;
    }
    // The PNG is written on the capture's threads: its row follows when the file is whole.
    if (export_format != capture::ExportFormat::None) {
      ParticleFrame f = solver.read_frame();
      to_world(f, solver.tank(), d.dt);
      capture::write_particles(dir.particle_path(frame), export_format, f, d.flows());
      if (solver.white_water_capacity() > 0) capture::write_white_water(dir.white_water_path(frame), export_format, f);
    }
    auto row = [&rows, &dir, frame, t, s, tank = solver.tank_pose(),
                poses = rows.solids ? solver.obstacle_poses() : std::vector<Pose>{},
                bodies = rows.bodies ? solver.bodies() : std::vector<Body>{}] {
      rows.stats.write(frame, t, s);
      if (rows.solids) rows.solids->write(frame, t, tank, poses);
      if (rows.bodies) rows.bodies->write(frame, t, bodies, poses);
      dir.frames_done(frame + 1);
    };
    if (capture)
      capture->write(dir.frame_path(frame), solver, row);
    else
      row();
    if (s.paused && !totals.paused)
      std::cerr << "pbflow: frame " << frame << ": the run holds its capacity of " << solver.capacity()
                << " particles; the emitters wait for room (scene key capacity)\n";
    totals.paused = totals.paused || s.paused;
    totals.energy.add(s);
    totals.sum_mean += s.mean_compression;
    totals.worst = std::max(totals.worst, s.max_compression);
    totals.sum_step_ms += s.step_ms;
    totals.sum_white_water_ms += s.white_water_ms;
    progress.update(frame, t, wall());
  }
  if (capture) capture->finish();  // the frames' files and rows, the video: also when stopped early
  progress.done();
  return totals;
}

// The summary on stdout: throughput, compression, energy, real-time factor, where things are.
void print_summary(const RunOptions& o, const Scene& scene, const RunTotals& totals, size_t particles,
                   const capture::FrameCapture* capture, double wall, const RunDirectory& dir) {
  const long steps = long(scene.frames - 1) * scene.solver.substeps;
  const double solver_s = totals.sum_step_ms / 1000.0 * scene.solver.substeps;
  const double render_s = capture ? capture->seconds() : 0.0, simulated_s = (scene.frames - 1) / scene.fps;
  std::cout << "particles " << particles << ", steps " << steps << ", wall " << wall << " s, "
            << (steps > 0 ? double(particles) * steps / solver_s : 0.0) << " particle-steps/s (solver time "
            << solver_s << " s), mean compression " << totals.sum_mean / scene.frames << ", max compression "
            << totals.worst;
  if (totals.sum_white_water_ms > 0)
    std::cout << ", white water " << totals.sum_white_water_ms / (scene.frames - 1) << " ms per frame ("
              << 100 * totals.sum_white_water_ms / totals.sum_step_ms << " % of a step)";
  std::cout << "\nenergy change " << 100 * totals.energy.last()
            << " % of the initial potential energy (largest gain " << 100 * totals.energy.largest()
            << " %)\nreal-time factor " << simulated_s / std::max(wall - render_s, 1e-9) << " simulating";
  if (capture)
    std::cout << ", " << simulated_s / wall << " with rendering (" << 1000.0 * render_s / scene.frames
              << " ms per frame, " << 1000.0 * capture->drawing_seconds() / scene.frames << " of it drawing, "
              << 1000.0 * capture->gpu_drawing_seconds() / scene.frames << " of that on the GPU)\nframes: "
              << (std::filesystem::path(o.out) / "frames").string() << "/";
  if (!o.video.empty()) std::cout << "\nvideo: " << o.video;
  std::cout << "\nstats: " << dir.stats_path().string() << "\n";
}

// Where the frames stopped early: the manifest says why and the exit status is returned (3
// diverged, 128 + the signal); 0 where they did not.
int stopped_early(const RunTotals& totals, const InterruptGuard& interrupt, RunDirectory& dir, double wall) {
  if (!totals.diverged.empty()) {
    std::cerr << "pbflow: " << totals.diverged << "\n";
    dir.end("diverged", totals.diverged, wall);
    return 3;
  }
  if (int signal = interrupt.signal()) {
    std::string m = "interrupted by " + std::string(signal_name(signal)) + "; " + frames_complete(totals.frames);
    std::cerr << "pbflow: " << m << "\n";
    dir.end("interrupted", m, wall);
    return 128 + signal;
  }
  return 0;
}

void warn_of_energy(const EnergyGain& energy) {
  if (energy.largest() > 0.01)
    std::cerr << "pbflow: warning: the run gained energy (" << 100 * energy.largest()
              << " % of the initial potential energy at most; a sound solver loses it): fewer "
                 "solver.substeps per iteration, more iterations or a smaller solver.ldc_strength\n";
}

// The run's end: complete, or failed where the validation layer or GL reported anything.
int finish(const vk::Context* ctx, const capture::FrameCapture* capture, RunDirectory& dir, double wall) {
  std::string problem;
  if (ctx && !ctx->validation_messages().empty())
    problem = std::to_string(ctx->validation_messages().size()) + " Vulkan validation message(s)";
  else if (capture && !capture->gl_errors().empty())
    problem = "OpenGL error: " + capture->gl_errors().front();
  dir.end(problem.empty() ? "complete" : "failed", problem, wall);
  if (!problem.empty()) std::cerr << "pbflow: " << problem << "\n";
  return problem.empty() ? 0 : 1;
}

}  // namespace

int run(const RunOptions& o) {
  // Before anything in --out changes: from here a SIGINT or SIGTERM stops the run between
  // steps, and never in the middle of replacing the previous run.
  InterruptGuard interrupt;
  if (!o.video.empty() && !o.render) throw InputError("--video needs frames to encode: leave out --no-render");
  Scene scene = load_scene(o.scene, scene_overrides(o));
  Derived d = derive(scene);
  const std::filesystem::path out(o.out);
  RunDirectory::check(out);  // before any work: a foreign file here is refused at once
  if (!o.video.empty()) check_video_outside(o.video, out);
  std::unique_ptr<vk::Context> ctx = make_context(o.device, o.validate);
  const vk::DeviceInfo* device = ctx ? &ctx->info() : nullptr;
  const MemoryNeed need = check_run_memory(o, scene, d, device);
  std::unique_ptr<Solver> solver = make_solver(ctx.get(), d, initial_particles(scene));
  const capture::ExportFormat export_format = capture::parse_export_format(o.export_format);
  std::unique_ptr<capture::FrameCapture> capture;
  if (o.render) capture = make_frame_capture(o, scene, {solver.get()}, ctx.get());
  const FrameOutputs outputs = run_outputs(o);
  const bool white_water = outputs_made(d, outputs).white_water;

  // Everything is checked: from here the run owns DIR and replaces the previous run's files.
  RunDirectory dir(out, RunFiles{scene.frames, bool(capture),
                                 export_format == capture::ExportFormat::None ? "" : capture::export_extension(export_format),
                                 white_water && export_format != capture::ExportFormat::None, d.moving(),
                                 !d.bodies.empty()});
  nlohmann::json about = describe_run(o, scene, d, *solver);
  const nlohmann::json chosen = about["chosen"];
  describe_machine(about, need, device, *solver);
  if (!dir.begin(std::move(about), [&] { return interrupt.signal() != 0; })) {
    std::cerr << "pbflow: interrupted by " << signal_name(interrupt.signal()) << " before the run began; "
              << out.string() << " holds the previous run as it was\n";
    return 128 + interrupt.signal();
  }
  const auto start = std::chrono::steady_clock::now();
  const std::function<double()> wall = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  RunTotals totals;
  try {
    FrameRows rows{StatsCsv(dir.stats_path()), d.moving() ? std::make_unique<SolidsCsv>(dir.solids_path()) : nullptr,
                   d.bodies.empty() ? nullptr : std::make_unique<BodiesCsv>(dir.bodies_path())};
    if (std::string w = time_step_warning(scene, d); !w.empty()) std::cerr << "pbflow: " << w << "\n";
    if (!o.quiet) announce(o, scene, d, chosen, *solver, capture.get(), white_water);
    Progress progress(scene.frames, !o.quiet);
    prepare_start(*solver, scene, d, o.quiet, progress, interrupt);
    solver->set_outputs(outputs);  // from the start on: none is made while it settles
    totals = simulate_frames(scene, d, *solver, capture.get(), export_format, dir, rows, progress, interrupt, wall);
    if (const int status = stopped_early(totals, interrupt, dir, wall()); status != 0) return status;
    warn_of_energy(totals.energy);
    if (!o.quiet) print_summary(o, scene, totals, solver->particle_count(), capture.get(), wall(), dir);
  } catch (const std::exception& e) {
    capture.reset();  // its writes in flight land now, so that end() takes the frames they cut short
    try {
      dir.end("failed", e.what(), wall());
    } catch (const std::exception&) {  // the disk that failed may refuse the manifest too: report the first error
    }
    throw;
  }
  return finish(ctx.get(), capture.get(), dir, wall());
}

}  // namespace pbflow
