#include "app/live_run.hpp"

#include <algorithm>
#include <cmath>
#include <future>
#include <iostream>

#include "capture/frame_capture.hpp"
#include "capture/stream/h264.hpp"
#include "capture/stream/jpeg.hpp"
#include "gpu/make_solver.hpp"
#include "scene/derive.hpp"
#include "scene/parse.hpp"
#include "scene/seeding.hpp"
#include "sim/settle.hpp"
#include "vk/context.hpp"

namespace pbflow {

namespace {

using Clock = std::chrono::steady_clock;

// Simulated over wall seconds, over windows of about a second.
class RealtimeFactor {
 public:
  void add(double simulated_s) {
    simulated_ += simulated_s;
    const double wall = std::chrono::duration<double>(Clock::now() - since_).count();
    if (wall >= 1.0) {
      value_ = simulated_ / wall;
      simulated_ = 0;
      since_ = Clock::now();
    }
  }
  void restart() { simulated_ = 0, since_ = Clock::now(); }
  double value() const { return value_; }

 private:
  double simulated_ = 0, value_ = 0;
  Clock::time_point since_ = Clock::now();
};

// A scene's method and iterations as the page shows them: "pbf@2".
std::string setting_name(const Scene& scene) {
  return std::string(method_name(scene.solver.method)) + "@" + std::to_string(scene.solver.iterations);
}

// The camera moved as a viewer's drag and wheel ask: orbit about the target (the pitch kept off
// the poles), the eye's distance scaled, the target panned in the view's plane.
Camera moved(Camera c, const LiveCommand& m) {
  glm::dvec3 offset = c.eye - c.target;
  const double distance = std::clamp(glm::length(offset) * m.zoom, 1e-6, 1e7);
  double yaw = std::atan2(offset.x, offset.z) - m.orbit_x;
  double pitch = std::clamp(std::asin(std::clamp(offset.y / glm::length(offset), -1.0, 1.0)) + m.orbit_y, -1.5, 1.5);
  offset = distance * glm::dvec3(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
  const glm::dvec3 forward = -offset / distance, right = glm::normalize(glm::cross(forward, glm::dvec3(0, 1, 0))),
                   up = glm::cross(right, forward);
  c.target += distance * (m.pan_x * right + m.pan_y * up);
  c.eye = c.target + offset;
  return c;
}

}  // namespace

LiveRun::LiveRun(const RunOptions& options) {
  std::promise<void> ready;
  std::future<void> started = ready.get_future();
  simulation_ = std::thread([this, options, &ready] { simulate(options, ready); });
  try {
    started.get();  // the set-up's error, rethrown here
  } catch (...) {
    simulation_.join();
    throw;
  }
  encoder_ = std::thread([this] { encode(); });
}

LiveRun::~LiveRun() {
  stop();
  if (simulation_.joinable()) simulation_.join();
  if (encoder_.joinable()) encoder_.join();
}

void LiveRun::stop() {
  stopping_ = true;
  {
    std::lock_guard lock(commands_mutex_);
    commands_changed_.notify_all();
  }
  std::lock_guard lock(frames_mutex_);
  drawn_changed_.notify_all();
  encoded_changed_.notify_all();
}

void LiveRun::command(LiveCommand c) {
  std::lock_guard lock(commands_mutex_);
  if (commands_.size() < 64) commands_.push_back(c);  // a flood of commands is cut, not queued
  commands_changed_.notify_all();
}

std::shared_ptr<const LiveFrame> LiveRun::next_frame(uint64_t after, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(frames_mutex_);
  encoded_changed_.wait_for(lock, timeout, [&] { return stopping_ || (encoded_ && encoded_->number > after); });
  return encoded_ && encoded_->number > after ? encoded_ : nullptr;
}

// The run's thread: the Vulkan device, the solver and the GL context live here. Frames go at
// the scene's clock: each is due a period after the last; one that is late is drawn at once
// and the clock starts again from it (the run then goes as fast as it can).
void LiveRun::simulate(const RunOptions& o, std::promise<void>& ready) {
  std::unique_ptr<vk::Context> ctx;
  std::unique_ptr<Solver> solver;
  std::unique_ptr<capture::FrameCapture> capture;
  Scene scene;
  ParticleState start;
  try {
    scene = load_scene(o.scene, scene_overrides(o));
    const Derived d = derive(scene);
    ctx = make_context(o.device, o.validate);
    const vk::DeviceInfo* device = ctx ? &ctx->info() : nullptr;
    check_run_memory(o, scene, d, device);
    solver = make_solver(ctx.get(), d, initial_particles(scene));
    capture = make_frame_capture(o, scene, *solver, ctx.get());
    solver->set_smoothed_positions(capture->draws_surface());
    relax_seed(*solver);
    if (scene.settle) settle(*solver, d);
    start = solver->download();
    description_ = scene.name + ", " + std::to_string(solver->particle_count()) + " particles, " +
                   setting_name(scene) + ", " +
                   std::to_string(scene.solver.substeps) + " substeps per frame, on " + solver->device_name();
    fps_ = scene.fps;  // before the encoder's thread starts, which reads it
    ready.set_value();
  } catch (...) {
    ready.set_exception(std::current_exception());
    return;
  }
  try {
    run_frames(o, scene, ctx.get(), solver, capture, start);
  } catch (const std::exception& e) {
    fail(e.what());
  }
}

void LiveRun::fail(const std::string& why) {
  {
    std::lock_guard lock(frames_mutex_);
    failure_ = why;
  }
  stop();
}

std::string LiveRun::failure() const {
  std::lock_guard lock(frames_mutex_);
  return failure_;
}

// The frames, at the scene's clock, and the viewers' commands between them.
void LiveRun::run_frames(const RunOptions& o, Scene& scene, const vk::Context* ctx, std::unique_ptr<Solver>& solver,
                         std::unique_ptr<capture::FrameCapture>& capture, const ParticleState& start) {
  RunOptions current = o;  // as the viewers have changed it
  std::string setting = setting_name(scene);
  // Another method or iteration count, or another style: the solver or the renderer made anew
  // on this thread, the particles carried over. The renderer shares the solver's buffers, so
  // it goes first and comes back after.
  auto rebuild = [&](bool new_solver) {
    const Camera camera = capture->camera();
    const ParticleState now = solver->download();
    capture.reset();
    if (new_solver) {
      scene = load_scene(current.scene, scene_overrides(current));
      solver = make_solver(ctx, derive(scene), initial_particles(scene));
      solver->upload(now);
      setting = setting_name(scene);
    }
    capture = make_frame_capture(current, scene, *solver, ctx);
    capture->set_camera(camera);
    solver->set_smoothed_positions(capture->draws_surface());
  };
  const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / scene.fps));
  RealtimeFactor realtime;
  uint64_t number = 0;
  double sim_time = 0;
  bool paused = false, first = true;
  Clock::time_point due = Clock::now();
  while (!stopping_) {
    bool step = false, redraw = false, new_solver = false, new_capture = false;
    {
      std::unique_lock lock(commands_mutex_);
      if (paused && commands_.empty()) commands_changed_.wait_for(lock, std::chrono::milliseconds(100));
      for (; !commands_.empty(); commands_.pop_front()) {
        const LiveCommand& c = commands_.front();
        switch (c.kind) {
          case LiveCommand::Kind::Pause: paused = true; break;
          case LiveCommand::Kind::Resume: paused = false; break;
          case LiveCommand::Kind::Step: step = paused = true; break;
          case LiveCommand::Kind::Restart: solver->upload(start), sim_time = 0, first = true; break;
          case LiveCommand::Kind::Setting:
            current.method = c.method, current.iterations = c.iterations, new_solver = redraw = true;
            break;
          case LiveCommand::Kind::Style: current.style = c.style, new_capture = redraw = true; break;
          case LiveCommand::Kind::Camera: capture->set_camera(moved(capture->camera(), c)), redraw = true; break;
        }
      }
    }
    if (stopping_) break;
    if (new_solver || new_capture) rebuild(new_solver);
    if (paused && !step && !first && !redraw) {
      realtime.restart();
      due = Clock::now();
      continue;
    }
    const bool advance = !first && (!paused || step);
    const Clock::time_point began = Clock::now();
    const FrameStats stats = solver->advance(advance ? scene.solver.substeps : 0);  // 0: measures, as shown
    const Clock::time_point simulated = Clock::now();
    if (advance) sim_time += 1.0 / scene.fps;
    realtime.add(advance ? 1.0 / scene.fps : 0.0);
    first = false;
    auto frame = std::make_shared<LiveFrame>();
    frame->number = ++number;
    frame->sim_time = sim_time;
    frame->stats = stats;
    frame->realtime_factor = paused ? 0.0 : realtime.value();
    frame->paused = paused;
    frame->setting = setting;
    auto image = std::make_shared<const capture::Image>(capture->draw(*solver));
    frame->simulate_ms = std::chrono::duration<double, std::milli>(simulated - began).count();
    frame->draw_ms = std::chrono::duration<double, std::milli>(Clock::now() - simulated).count();
    frame->drawn_unix_ms =
        std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch()).count();
    {
      std::lock_guard lock(frames_mutex_);  // the encoder takes the newest; one it missed is dropped
      drawn_ = std::move(frame);
      drawn_image_ = std::move(image);
      drawn_changed_.notify_all();
    }
    due += period;
    const Clock::time_point now = Clock::now();
    if (now < due) std::this_thread::sleep_until(due);
    else if (now - due > period) due = now;  // behind: as fast as it can, the clock from here
  }
}

// The encoder's thread: JPEG for every frame it takes, and H.264 while a viewer takes it, made
// when the first such viewer asks (the image's size is fixed for the run).
void LiveRun::encode() {
  try {
    encode_frames();
  } catch (const std::exception& e) {
    fail(e.what());
  }
}

void LiveRun::encode_frames() {
  capture::JpegEncoder jpeg;
  std::unique_ptr<capture::H264Encoder> h264;
  bool h264_failed = false;
  uint64_t last = 0, unit = 0;
  while (!stopping_) {
    std::shared_ptr<LiveFrame> frame;
    std::shared_ptr<const capture::Image> image;
    {
      std::unique_lock lock(frames_mutex_);
      drawn_changed_.wait(lock, [&] { return stopping_ || (drawn_ && drawn_->number > last); });
      if (stopping_) return;
      frame = drawn_;
      image = drawn_image_;
    }
    last = frame->number;
    auto encoded = std::make_shared<LiveFrame>(*frame);
    const Clock::time_point began = Clock::now();
    encoded->jpeg = jpeg.encode(*image);
    if (h264_viewers_ > 0 && !h264_failed) {
      if (!h264) {
        // About 0.1 bit a pixel a frame: 720p at 60 fps within 6 Mbit/s, the rate a real network carries.
        const double rate = std::clamp(0.1 * image->width * image->height * fps_, 2e5, 6e6);
        try {
          h264 = std::make_unique<capture::H264Encoder>(image->width, image->height,
                                                        std::max(1, int(std::lround(fps_))), rate);
        } catch (const std::exception& e) {  // the viewers that asked for it get JPEG
          std::cerr << "pbflow: no H.264 stream: " << e.what() << "\n";
          h264_failed = true;
          h264_broken_ = true;
        }
        keyframe_wanted_ = true;
      }
    }
    if (h264 && h264_viewers_ > 0) {
      capture::H264Encoder::Unit u = h264->encode(*image, keyframe_wanted_.exchange(false));
      encoded->h264 = std::move(u.bytes);
      encoded->keyframe = u.keyframe;
      encoded->unit = ++unit;
    }
    encoded->encode_ms = std::chrono::duration<double, std::milli>(Clock::now() - began).count();
    std::lock_guard lock(frames_mutex_);
    encoded_ = std::move(encoded);
    encoded_changed_.notify_all();
  }
}

}  // namespace pbflow
