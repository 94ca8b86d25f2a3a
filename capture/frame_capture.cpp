#include "capture/frame_capture.hpp"

#include <chrono>


namespace pbflow::capture {

FrameCapture::FrameCapture(const CaptureOptions& options, const Solver& solver, const vk::Context* vk)
    : options_(options), gl_(gl::Context::Options{options.debug}), renderer_(options.view) {
  transfer_ = make_particle_transfer(solver, vk, gl_, options.allow_shared);
  // llvmpipe compiles a GL program's shaders at its first draw (~130 ms for the fluid
  // style at 720p) where the solver's pipelines are compiled as it is made: one render of
  // the particles, never written, does it here, before the run's first frame and clock.
  renderer_.render(transfer_->update(solver), uint32_t(solver.particle_count()));
  if (!options.video.empty())
    video_ = std::make_unique<VideoEncoder>(options.video, options.view.width, options.view.height, options.fps);
}

FrameCapture::~FrameCapture() = default;

const Image& FrameCapture::draw(const Solver& solver) {
  const auto start = std::chrono::steady_clock::now();
  const Image& image = renderer_.render(transfer_->update(solver), uint32_t(solver.particle_count()));
  drawing_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  gpu_drawing_seconds_ += renderer_.last_gpu_seconds();
  return image;
}

void FrameCapture::write(const std::filesystem::path& png, const Solver& solver, std::function<void()> written) {
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  const Image& image = draw(solver);
  if (video_) video_->add(image);
  writer_.push(png, image, std::move(written));  // a copy: the renderer draws the next frame into its own
  seconds_ += std::chrono::duration<double>(clock::now() - start).count();
}

void FrameCapture::finish() {
  const auto start = std::chrono::steady_clock::now();
  writer_.finish();
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (video_) video_->finish();
  video_.reset();
}

std::string FrameCapture::description() const {
  return gl_.description() + "; particles by " + transfer_->name();
}

}  // namespace pbflow::capture
