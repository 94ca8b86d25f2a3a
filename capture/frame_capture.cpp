#include "frame_capture.hpp"

#include <chrono>
#include <cstdio>

#include "png.hpp"

namespace pbflow::capture {

FrameCapture::FrameCapture(const CaptureOptions& options, const Solver& solver, const vk::Context* vk)
    : options_(options), gl_(gl::Context::Options{options.debug}), renderer_(options.view) {
  transfer_ = make_particle_transfer(solver, vk, gl_, options.allow_shared);
  if (!options.video.empty())
    video_ = std::make_unique<VideoEncoder>(options.video, options.view.width, options.view.height, options.fps);
  digits_ = std::max(5, int(std::to_string(std::max(options.frame_count - 1, 0)).size()));
  std::filesystem::create_directories(options.frames_dir);
}

FrameCapture::~FrameCapture() = default;

std::filesystem::path FrameCapture::frame_path(int frame) const {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%0*d.png", digits_, frame);
  return options_.frames_dir / name;
}

void FrameCapture::write(int frame, const Solver& solver) {
  auto start = std::chrono::steady_clock::now();
  Image image = renderer_.render(transfer_->update(solver), uint32_t(solver.particle_count()));
  write_png(frame_path(frame), image);
  if (video_) video_->add(image);
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void FrameCapture::finish() {
  if (video_) video_->finish();
  video_.reset();
}

std::string FrameCapture::description() const {
  return gl_.description() + "; particles by " + transfer_->name();
}

}  // namespace pbflow::capture
