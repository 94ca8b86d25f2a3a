#pragma once
// The capture stage of a run: after each frame, particles to GL, render, write the
// frame's PNG, and feed the video when one is asked for.
#include <filesystem>
#include <memory>
#include <string>

#include "capture/gl_context.hpp"
#include "capture/particle_transfer.hpp"
#include "capture/renderer.hpp"
#include "capture/video.hpp"

namespace pbflow::capture {

struct CaptureOptions {
  View view;
  std::filesystem::path video;       // empty: none
  double fps = 60;
  bool allow_shared = true;  // false forces the read-back path
  bool debug = false;        // GL debug context; errors() reports what it saw
};

class FrameCapture {
 public:
  // Makes the GL context and checks everything it can before any frame is written.
  FrameCapture(const CaptureOptions& options, const Solver& solver, const vk::Context* vk);
  ~FrameCapture();

  void write(const std::filesystem::path& png, const Solver& solver);
  void finish();  // completes the video

  std::string description() const;  // GL platform, renderer and transfer path
  double seconds() const { return seconds_; }  // spent rendering and writing so far
  double drawing_seconds() const { return drawing_seconds_; }  // of which particles to GL, drawing, reading back
  double gpu_drawing_seconds() const { return gpu_drawing_seconds_; }  // the GPU's time drawing (timer queries)
  std::vector<std::string> gl_errors() const { return gl_.errors(); }

 private:
  CaptureOptions options_;
  gl::Context gl_;
  Renderer renderer_;
  std::unique_ptr<ParticleTransfer> transfer_;
  std::unique_ptr<VideoEncoder> video_;
  double seconds_ = 0, drawing_seconds_ = 0, gpu_drawing_seconds_ = 0;
};

}  // namespace pbflow::capture
