#include "capture/frame_capture.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>


namespace pbflow::capture {

FrameCapture::FrameCapture(const CaptureOptions& options, const std::vector<const Solver*>& solvers,
                           const vk::Context* vk)
    : options_(options), gl_(gl::Context::Options{options.debug, options.device_uuid}), renderer_(options.view) {
  for (const Solver* solver : solvers)
    transfers_.push_back(make_particle_transfer(*solver, vk, gl_, options.allow_shared));
  // llvmpipe compiles a GL program's shaders at its first draw where the solver's pipelines
  // are compiled as it is made: one render of the particles, never written, does it here,
  // before the run's first frame and clock.
  renderer_.render(transfers_[0]->update(*solvers[0]), uint32_t(solvers[0]->particle_count()),
                   uint32_t(solvers[0]->white_water_capacity()));
  if (solvers.size() > 1) {
    panels_.width = options.view.width * int(solvers.size());
    panels_.height = options.view.height;
    panels_.rgb.resize(size_t(panels_.width) * panels_.height * 3);
  }
  if (!options.video.empty())
    video_ = std::make_unique<VideoEncoder>(options.video, options.view.width, options.view.height, options.fps);
}

FrameCapture::~FrameCapture() = default;

const Image& FrameCapture::draw(const Solver& solver) { return draw(std::vector<const Solver*>{&solver}); }

const Image& FrameCapture::draw(const std::vector<const Solver*>& solvers) {
  if (solvers.size() != transfers_.size())
    throw std::logic_error("FrameCapture::draw: " + std::to_string(solvers.size()) + " solvers for " +
                           std::to_string(transfers_.size()) + " panels");
  const auto start = std::chrono::steady_clock::now();
  const Image* image = nullptr;
  for (size_t i = 0; i < solvers.size(); ++i) {
    renderer_.set_poses(solvers[i]->tank_pose(), solvers[i]->obstacle_poses());
    image = &renderer_.render(transfers_[i]->update(*solvers[i]), uint32_t(solvers[i]->particle_count()),
                              uint32_t(solvers[i]->white_water_capacity()));
    gpu_drawing_seconds_ += renderer_.last_gpu_seconds();
    if (solvers.size() == 1) break;
    const size_t row = size_t(image->width) * 3;
    for (int y = 0; y < image->height; ++y)
      std::copy_n(image->rgb.data() + y * row, row, panels_.rgb.data() + (y * panels_.width + i * image->width) * 3);
  }
  drawing_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return solvers.size() == 1 ? *image : panels_;
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
  return gl_.description() + "; particles by " + transfers_[0]->name();
}

}  // namespace pbflow::capture
