// pbflow command line: run, serve, bench, scenes, devices, keys, diff.
#include <CLI/CLI.hpp>
#include <malloc.h>

#include <cmath>
#include <csignal>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string_view>

#include "app/diff.hpp"
#include "app/run.hpp"
#include "app/serve.hpp"
#include "bench/scaling.hpp"
#include "bench/study.hpp"
#include "capture/gl_context.hpp"
#include "capture/renderer.hpp"
#include "scene/keys.hpp"
#include "scene/parse.hpp"
#include "scene/scene.hpp"
#include "vk/check.hpp"
#include "vk/context.hpp"

namespace {

int list_devices() {
  auto devices = pbflow::vk::Context::list_devices();
  if (devices.empty()) std::cout << "no Vulkan devices (install mesa-vulkan-drivers for lavapipe)\n";
  for (const auto& d : devices)
    std::printf("%u  %-40s %-10s Vulkan %u.%u  %6.1f GiB  max workgroup %u  timestamps %s%s\n", d.index,
                d.name.c_str(), d.kind.c_str(), VK_API_VERSION_MAJOR(d.api_version),
                VK_API_VERSION_MINOR(d.api_version), double(d.device_local_bytes) / (1 << 30),
                d.max_workgroup_invocations, d.timestamps ? "yes" : "no", d.usable ? "" : "  (not usable)");
  std::cout << "cpu  the C++ reference solver (--device cpu)\n";
  return 0;
}

int list_scenes() {
  for (const auto& s : pbflow::builtin_scenes()) std::printf("%-18s %s\n", s.name.c_str(), s.description.c_str());
  return 0;
}

// --scaling takes the study's options that make sense for one scene and one setting.
pbflow::bench::ScalingOptions scaling_options(const pbflow::bench::StudyOptions& b, double budget_minutes,
                                              const std::string& method) {
  if (b.scenes.size() > 1 || b.iterations.size() > 1)
    throw pbflow::InputError("--scaling runs one scene at one iteration count: give at most one of each");
  if (b.stability || b.quick || !b.targets.empty() || !b.substeps.empty() || !b.ldc_strength.empty())
    throw pbflow::InputError(
        "--scaling takes --counts, --scenes, --method, --iterations, --seconds and --budget-minutes only");
  pbflow::bench::ScalingOptions o;
  o.out = b.out;
  o.device = b.device;
  if (!b.scenes.empty()) o.scene = b.scenes[0];
  o.counts = b.counts;
  if (!b.iterations.empty()) o.iterations = b.iterations[0];
  o.method = method;
  if (b.seconds > 0) o.seconds = b.seconds;
  o.budget_minutes = budget_minutes;
  o.charts = b.charts;
  return o;
}

// A number option that is not NaN or infinite: CLI11's ranges let NaN through, since every
// comparison with it is false. For a list option it checks every element.
const CLI::Validator kFinite(
    [](std::string& text) -> std::string {
      try {
        size_t used = 0;
        const double value = std::stod(text, &used);
        if (used == text.size() && std::isfinite(value)) return "";
      } catch (const std::exception&) {
      }
      return "'" + text + "' is not a finite number";
    },
    "FINITE");

// The argument as a message can show it: bytes past ASCII as \xNN.
std::string printable(std::string_view text) {
  std::string out;
  for (unsigned char c : text) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "\\x%02x", c);
    out += c >= 0x20 && c < 0x7f ? std::string(1, char(c)) : std::string(hex);
  }
  return out;
}

// Every argument must be UTF-8: a run records its names and values (the scene, --out, --video,
// --param) in JSON, which holds nothing else. Refused here, before anything is read or written,
// naming the option it belongs to.
void check_utf8(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    try {
      (void)nlohmann::json(argv[i]).dump();
    } catch (const nlohmann::json::exception&) {
      const std::string arg = argv[i];
      const bool value = i > 1 && argv[i - 1][0] == '-' && arg[0] != '-';
      const std::string option = value ? argv[i - 1] : arg.substr(0, arg.find('='));
      throw pbflow::InputError((value || option[0] == '-' ? "the value of " + printable(option) : "the argument") + " '" +
                               printable(arg) + "' is not valid UTF-8 (pbflow records names and values in JSON)");
    }
  }
}

// Every subcommand's options, as the command line fills them.
struct Commands {
  pbflow::RunOptions run;
  bool no_render = false;
  pbflow::ServeOptions serve;
  pbflow::bench::StudyOptions bench;
  bool scaling = false, no_charts = false;
  double budget_minutes = pbflow::bench::ScalingOptions{}.budget_minutes;
  std::string scaling_method;
  std::string diff_a, diff_b;  // `pbflow diff A B`
};

int run_command(CLI::App& app, const Commands& c);
int written(int status);

// The options `run` and `serve` share: the scene, its setting, the device and the image.
void add_scene_options(CLI::App* cmd, pbflow::RunOptions& o) {
  cmd->add_option("scene", o.scene, "built-in scene name or JSON file");
  cmd->add_option("--method", o.method, "pbf | ldc")->check(CLI::IsMember({"pbf", "ldc"}));
  cmd->add_option("--iterations", o.iterations, "constraint iterations per step")->check(CLI::Range(1, 1000));
  cmd->add_option("--device", o.device, "auto | cpu | INDEX (see 'pbflow devices')")->capture_default_str();
  cmd->add_option("--param", o.params, "override a scene key, e.g. solver.ldc_k=2000 (repeatable)");
  cmd->add_flag("--validate", o.validate, "enable the Vulkan validation layer");
  std::vector<std::string> styles;
  for (pbflow::capture::Style s : pbflow::capture::kStyles) styles.push_back(pbflow::capture::style_name(s));
  cmd->add_option("--style", o.style, "how frames are drawn: fluid (the default), particles, density, speed or "
                                            "normals (the fluid's surface normals, RGB = 0.5 n + 0.5)")
      ->check(CLI::IsMember(styles))
      ->capture_default_str();
  cmd->add_option("--fluid-resolution", o.fluid_resolution,
                      "fluid style: the surface's depth, thickness and smoothing at half or full image size")
      ->check(CLI::IsMember({"half", "full"}))
      ->capture_default_str();
  cmd->add_option("--width", o.width, "image width in pixels")->check(CLI::Range(16, 16384))->capture_default_str();
  cmd->add_option("--height", o.height, "image height in pixels")
      ->check(CLI::Range(16, 16384))
      ->capture_default_str();
}


// `pbflow run`: the scene options and where and how a run writes its frames.
void add_run_command(CLI::App& app, Commands& c) {
  CLI::App* run_cmd = app.add_subcommand("run", "simulate a scene (default: dam_break)");
  add_scene_options(run_cmd, c.run);
  run_cmd->add_option("--frames", c.run.frames, "frames to write (frame 0 is the initial state)")
      ->check(CLI::Range(1, pbflow::kMaxFrames));
  run_cmd->add_option("--out", c.run.out, "output directory")->capture_default_str();
  run_cmd->add_flag("--quiet", c.run.quiet, "no progress line or summary");
  run_cmd->add_flag("--no-render", c.no_render, "simulate only, write no images");
  run_cmd->add_option("--video", c.run.video, "also encode the frames into this .mp4 (needs ffmpeg)");
  run_cmd->add_flag("--readback", c.run.readback, "read particles back through the host even where zero-copy works");
  run_cmd->add_option("--export", c.run.export_format, "particle files per frame: ply | vtk (.vtp)")
      ->check(CLI::IsMember({"ply", "vtk"}));
  run_cmd->add_flag("--verbose", c.run.verbose, "say how frames are rendered (EGL platform, GL, particle path)");

}

// `pbflow serve`: the scene options, the live view's own, and where it listens.
void add_serve_command(CLI::App& app, Commands& c) {
  c.serve.live.run.width = 640;  // a live view's default: what a CPU device holds near real time (docs/serve.md)
  c.serve.live.run.height = 360;
  CLI::App* serve_cmd = app.add_subcommand("serve", "run a scene live and watch it in a browser (docs/serve.md)");
  add_scene_options(serve_cmd, c.serve.live.run);
  serve_cmd
      ->add_option_function<std::vector<std::string>>(
          "--compare",
          [&c](const std::vector<std::string>& settings) {
            for (const std::string& s : settings) try {
                c.serve.live.compare.push_back(pbflow::parse_live_setting(s));
              } catch (const pbflow::InputError& e) {
                throw CLI::ValidationError("--compare", e.what());
              }
          },
          "settings side by side from one start, e.g. pbf@1,ldc@1,pbf@2 (each panel --width x --height, "
          "480x270 unless given)")
      ->delimiter(',');
  serve_cmd->add_option("--frame-budget", c.serve.live.frame_budget_ms,
                        "hold a frame within MS milliseconds by choosing the most accurate setting that fits")
      ->check(kFinite & CLI::Range(0.0, 10000.0));
  serve_cmd->add_option("--listen", c.serve.listen, "ADDRESS:PORT to serve on, one numeric address ([::1] for IPv6); "
                                                  "beyond loopback, steering needs the token it prints")
      ->capture_default_str();

}

// `pbflow bench`: the study's grid of settings, or the scaling run.
void add_bench_command(CLI::App& app, Commands& c) {
  CLI::App* bench_cmd = app.add_subcommand("bench", "the speed-accuracy study: CSV and charts (bench/study.hpp)");
  bench_cmd->add_flag("--quick", c.bench.quick, "a small subset: 4000 particles, 1 to 3 iterations, 1 s");
  bench_cmd->add_option("--out", c.bench.out, "output directory")->capture_default_str();
  bench_cmd->add_option("--device", c.bench.device, "auto | cpu | INDEX")->capture_default_str();
  bench_cmd->add_option("--counts", c.bench.counts, "particle counts, e.g. 10000,40000")->delimiter(',');
  bench_cmd->add_option("--iterations", c.bench.iterations, "iteration counts, e.g. 1,2,3")->delimiter(',');
  bench_cmd->add_option("--seconds", c.bench.seconds, "simulated seconds per run")
      ->check(kFinite & CLI::Range(0.001, 3600.0));
  bench_cmd->add_option("--ldc-strength", c.bench.ldc_strength,
                        "sweep the LDC strength (fraction of the step's limit), e.g. 0.25,0.5,0.9")
      ->delimiter(',')
      ->check(kFinite);
  bench_cmd->add_option("--targets", c.bench.targets, "adaptive runs to these mean compressions, e.g. 0.01,0.001")
      ->delimiter(',')
      ->check(kFinite);
  bench_cmd->add_option("--substeps", c.bench.substeps, "steps per frame to try, e.g. 1,2,4")->delimiter(',');
  bench_cmd->add_flag("--stability", c.bench.stability,
                      "the stability map: dam_break and drop, substeps x iterations x LDC strength, each run classified");
  bench_cmd->add_option("--scenes", c.bench.scenes, "scenes, e.g. dam_break,drop (default dam_break,hydrostatic)")
      ->delimiter(',');
  bench_cmd->add_flag("--scaling", c.scaling,
                      "the cost model: one scene (--scenes, default dam_break) at doubling particle counts from 10 000 "
                      "to 4 000 000, ms per step, bytes per particle, per-pass split, the fit");
  bench_cmd->add_option("--budget-minutes", c.budget_minutes, "with --scaling: start no count that would end past this")
      ->check(kFinite & CLI::PositiveNumber)
      ->capture_default_str();
  bench_cmd->add_option("--method", c.scaling_method, "with --scaling: pbf or ldc (default: the scene's)")
      ->check(CLI::IsMember({"pbf", "ldc"}));
  bench_cmd->add_flag("--no-charts", c.no_charts, "CSV only");

}

}  // namespace

int main(int argc, char** argv) {
  std::signal(SIGPIPE, SIG_IGN);  // a dying ffmpeg shows as a failed write, not a silent exit
  std::signal(SIGXFSZ, SIG_IGN);  // past a file size limit a write fails (EFBIG) and is reported
  // Freed memory stays with the process: the libraries that draw and write a frame allocate
  // and free a few megabytes each time, and handing them back to the kernel made every frame
  // fault them in again (docs/rendering.md, "More on cost").
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  CLI::App app{"pbflow: position based fluids with local density correction, on Vulkan compute"};
  app.set_version_flag("--version", std::string("pbflow ") + PBFLOW_VERSION);
  app.require_subcommand(0, 1);
  Commands c;
  add_run_command(app, c);
  add_serve_command(app, c);
  add_bench_command(app, c);
  app.add_subcommand("scenes", "list the built-in scenes");
  app.add_subcommand("devices", "list the Vulkan devices and their limits");
  app.add_subcommand("keys", "list every scene key: default, range, unit, meaning (Markdown)");
  CLI::App* diff_cmd = app.add_subcommand("diff", "compare two run directories: exit 0 when equal, 1 naming the first difference");
  diff_cmd->add_option("A", c.diff_a, "a run directory (the golden one)")->required();
  diff_cmd->add_option("B", c.diff_b, "another run directory")->required();

  try {
    check_utf8(argc, argv);
  } catch (const pbflow::InputError& e) {
    std::cerr << "pbflow: " << e.what() << "\n";
    return 2;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return written(app.exit(e));
  } catch (const CLI::ParseError& e) {
    std::cerr << "pbflow: " << e.what() << "\n";
    return 2;
  }
  c.run.render = !c.no_render;
  c.bench.charts = !c.no_charts;
  CLI::App* serve_cmd = app.get_subcommand("serve");
  if (!c.serve.live.compare.empty() && serve_cmd->count("--width") == 0) c.serve.live.run.width = 480;
  if (!c.serve.live.compare.empty() && serve_cmd->count("--height") == 0) c.serve.live.run.height = 270;

  return written(run_command(app, c));
}

namespace {

// What was printed must have reached its reader: `pbflow keys > /dev/full` (or into a closed
// stdout) is a failure, `--help` and `--version` among them.
int written(int status) {
  std::cout.flush();
  if (std::fflush(stdout) != 0 || std::ferror(stdout) || !std::cout) {
    std::cerr << "pbflow: cannot write the output: " << std::strerror(errno ? errno : EIO) << "\n";
    return status == 0 ? 1 : status;
  }
  return status;
}

int run_command(CLI::App& app, const Commands& c) {
  CLI::App* scenes_cmd = app.get_subcommand("scenes");
  CLI::App* devices_cmd = app.get_subcommand("devices");
  CLI::App* keys_cmd = app.get_subcommand("keys");
  CLI::App* bench_cmd = app.get_subcommand("bench");
  CLI::App* serve_cmd = app.get_subcommand("serve");
  try {
    if (*serve_cmd) return pbflow::serve(c.serve);
    if (*scenes_cmd) return list_scenes();
    if (*devices_cmd) return list_devices();
    if (*keys_cmd) return std::cout << pbflow::scene_keys_markdown(), 0;
    if (*app.get_subcommand("diff")) return pbflow::diff_runs(c.diff_a, c.diff_b, std::cout);
    if (!c.scaling_method.empty() && !c.scaling)
      throw pbflow::InputError("--method is for --scaling (the study runs both)");
    if (*bench_cmd && c.scaling)
      return pbflow::bench::run_scaling(scaling_options(c.bench, c.budget_minutes, c.scaling_method));
    if (*bench_cmd) return pbflow::bench::run_study(c.bench);
    return pbflow::run(c.run);  // `pbflow` alone runs the default scene
  } catch (const pbflow::InputError& e) {
    std::cerr << "pbflow: " << e.what() << "\n";
    return 2;
  } catch (const pbflow::gl::Error& e) {  // no EGL/GL: the machine cannot render; --no-render still works
    std::cerr << "pbflow: cannot render: " << e.what() << " (--no-render simulates without images)\n";
    return 1;
  } catch (const pbflow::vk::DeviceSelectionError& e) {
    std::cerr << "pbflow: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "pbflow: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace
