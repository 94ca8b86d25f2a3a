#pragma once
// The capture stage of a run: after each frame, particles to GL, render, feed the video when
// one is asked for, and hand the frame's PNG to the writer's threads.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "capture/frame_writer.hpp"
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
  std::optional<gl::Context::Uuid> device_uuid;  // the solver's Vulkan device: drawn on that one (gl::Context)
};

class FrameCapture {
 public:
  // Makes the GL context and checks everything it can before any frame is written.
  FrameCapture(const CaptureOptions& options, const Solver& solver, const vk::Context* vk)
      : FrameCapture(options, std::vector<const Solver*>{&solver}, vk) {}
  // Several solvers of one scene drawn side by side, each in a panel of the view's size, one
  // camera for all (the live view's comparison): images of panels x the view's width.
  FrameCapture(const CaptureOptions& options, const std::vector<const Solver*>& solvers, const vk::Context* vk);
  ~FrameCapture();

  // Draws the solver's frame and starts writing it to `png`; `written` runs once the file is
  // whole, in frame order (FrameWriter), here or in a later write() or finish().
  void write(const std::filesystem::path& png, const Solver& solver, std::function<void()> written);
  // Draws the solver's frame and returns the image (the renderer's own, valid until the next
  // draw): what the live view encodes, and what write() writes.
  const Image& draw(const Solver& solver);
  const Image& draw(const std::vector<const Solver*>& solvers);  // one a panel, as constructed
  void set_camera(const Camera& camera) { renderer_.set_camera(camera); }
  const Camera& camera() const { return renderer_.view().camera; }
  void finish();  // waits for the frames' files, then completes the video

  std::string description() const;  // GL platform, renderer and transfer path
  // What a frame drawn in this capture's style needs of the solver (frame_outputs).
  FrameOutputs outputs() const { return frame_outputs(&renderer_.view().style, false); }
  double seconds() const { return seconds_; }  // the run's time in write() and finish() so far
  double drawing_seconds() const { return drawing_seconds_; }  // of which particles to GL, drawing, reading back
  double gpu_drawing_seconds() const { return gpu_drawing_seconds_; }  // the GPU's time drawing (timer queries)
  std::vector<std::string> gl_errors() const { return gl_.errors(); }

 private:
  CaptureOptions options_;
  gl::Context gl_;
  Renderer renderer_;
  std::vector<std::unique_ptr<ParticleTransfer>> transfers_;  // one a panel
  Image panels_;  // where there are several: each panel's image copied in beside the last
  std::unique_ptr<VideoEncoder> video_;
  FrameWriter writer_{FrameWriter::default_in_flight()};
  double seconds_ = 0, drawing_seconds_ = 0, gpu_drawing_seconds_ = 0;
};

}  // namespace pbflow::capture
