#pragma once
// `pbflow run`: scene -> solver -> stats.csv, with progress and a summary.
#include <memory>
#include <string>
#include <vector>

#include "gpu/memory_estimate.hpp"
#include "sim/params.hpp"
#include "sim/solver.hpp"

namespace pbflow {

namespace vk {
class Context;
struct DeviceInfo;
}

struct RunOptions {
  std::string scene = "dam_break";
  std::vector<std::string> params;  // --param key=value, applied in order
  std::string method;               // empty: the scene's
  int iterations = 0;               // 0: the scene's
  int frames = 0;                   // 0: the scene's
  std::string out = "out";
  std::string device = "auto";
  bool validate = false;
  bool render = true;
  bool quiet = false;
  bool verbose = false;
  // Rendering (capture/): image size, style, video file, and the particle path.
  int width = 1280, height = 720;
  std::string style = "fluid";
  std::string fluid_resolution = "half";  // the fluid surface's passes: "half" or "full" size
  std::string video;      // empty: no video
  bool readback = false;  // force the read-back path even where zero-copy works
  std::string export_format;  // "", "ply" or "vtk": DIR/particles/frame_NNNNN.{ply,vtp}
};

// The scene's overrides: --param entries, then the dedicated options (which win).
std::vector<std::string> scene_overrides(const RunOptions& o);

namespace capture {
class FrameCapture;
}
struct Scene;

// The renderer of `o`'s image options for `scene`, drawing the solvers' frames (several: side
// by side, each in a panel of `o`'s size) and its video, where `o` names one. Throws InputError
// for a bad size or style.
std::unique_ptr<capture::FrameCapture> make_frame_capture(const RunOptions& o, const Scene& scene,
                                                          const std::vector<const Solver*>& solvers,
                                                          const vk::Context* vk);

// What each frame of the run of `o` must produce for its capture and export (capture::frame_outputs).
FrameOutputs run_outputs(const RunOptions& o);

// What the run of `o` needs, checked against `device` (null: the reference solver) and the
// host before anything is allocated: InputError with the numbers and the option to change.
// `solvers`: that many of the scene side by side (the live view's comparison).
MemoryNeed check_run_memory(const RunOptions& o, const Scene& scene, const Derived& d, const vk::DeviceInfo* device,
                            size_t solvers = 1);

// Runs the scene; returns the exit status (docs/design.md). Throws InputError for bad input.
int run(const RunOptions& o);

}  // namespace pbflow
