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

namespace pbflow {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

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

// The scene of `o` under `s`: its method and iterations, and its substeps where `s` names them.
Scene lane_scene(RunOptions o, const LiveSetting& s) {
  o.method = s.method;
  o.iterations = s.iterations;
  if (s.substeps > 0) o.params.push_back("solver.substeps=" + std::to_string(s.substeps));
  return load_scene(o.scene, scene_overrides(o));
}

LiveSetting setting_of(const Scene& scene) {
  return {method_name(scene.solver.method), scene.solver.iterations, scene.solver.substeps};
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

// One solver of the run and its setting: a run has one, --compare one a setting.
struct Lane {
  LiveSetting setting;  // substeps resolved
  std::unique_ptr<Solver> solver;
};

// What the run's thread simulates and draws: the scene, its lanes from one start, and the
// renderer that draws them all (it shares the solvers' buffers: made after them, gone before).
struct LiveRun::Stage {
  RunOptions options;  // as the viewers have changed them (scene, style)
  Scene scene;         // the first lane's
  int scene_substeps = 1;  // the scene's own, before any setting: the frame budget's base
  std::vector<Lane> lanes;
  ParticleState start;  // relaxed and, for a tank, settled: every lane starts and restarts here
  std::unique_ptr<capture::FrameCapture> capture;

  std::vector<const Solver*> solvers() const {
    std::vector<const Solver*> all;
    for (const Lane& lane : lanes) all.push_back(lane.solver.get());
    return all;
  }
  // The scene's lanes, one a setting (none given: the scene's own), from the first's relaxed
  // start, and their renderer: what a run starts with and a new scene brings.
  void load(const RunOptions& o, const std::vector<LiveSetting>& settings, const vk::Context* ctx) {
    capture.reset();
    lanes.clear();
    options = o;
    const Scene base = load_scene(o.scene, scene_overrides(o));
    scene_substeps = base.solver.substeps;
    for (const LiveSetting& s : settings.empty() ? std::vector<LiveSetting>{setting_of(base)} : settings) {
      const Scene lane = lane_scene(o, s);
      if (lanes.empty()) scene = lane;
      lanes.push_back({setting_of(lane), make_solver(ctx, derive(lane), initial_particles(lane))});
    }
    Solver& first = *lanes[0].solver;
    project_start(first);
    if (scene.settle) settle(first, derive(scene));
    start = first.download();
    for (Lane& lane : lanes) lane.solver->upload(start);
    draw_anew(ctx, scene.camera);
  }
  // The first lane under another setting, its particles carried over.
  void change_setting(const LiveSetting& s, const vk::Context* ctx) {
    const Camera camera = capture->camera();
    const ParticleState now = lanes[0].solver->download();
    capture.reset();
    make_first(s, ctx);
    lanes[0].solver->upload(now);
    draw_anew(ctx, camera);
  }
  // The first lane's solver made anew under `s`, at the scene's start; the renderer, which
  // shares its buffers, must be gone.
  void make_first(const LiveSetting& s, const vk::Context* ctx) {
    scene = lane_scene(options, s);
    lanes[0].solver.reset();  // before the next is made: one solver's memory at a time
    lanes[0] = {setting_of(scene), make_solver(ctx, derive(scene), initial_particles(scene))};
  }
  void draw_anew(const vk::Context* ctx, Camera camera) {  // by value: it may be the old renderer's
    capture.reset();
    capture = make_frame_capture(options, scene, solvers(), ctx);
    capture->set_camera(camera);
    for (Lane& lane : lanes) {
      lane.solver->set_smoothed_positions(capture->draws_surface());
      lane.solver->set_white_water(capture->draws_white_water());
    }
  }
  std::string about() const {
    std::string settings;
    for (const Lane& lane : lanes) settings += (settings.empty() ? "" : " | ") + lane.setting.name();
    return scene.name + ", " + std::to_string(lanes[0].solver->particle_count()) + " particles, " + settings + ", " +
           std::to_string(scene.solver.substeps) + " substeps per frame, on " + lanes[0].solver->device_name();
  }
};

LiveRun::LiveRun(const LiveOptions& options)
    : options_(options.run), panels_(std::max<size_t>(1, options.compare.size())) {
  if (options.compare.size() > kMaxPanels)
    throw InputError("--compare takes at most " + std::to_string(kMaxPanels) + " settings");
  if (!options.compare.empty() && options.frame_budget_ms > 0)
    throw InputError("--frame-budget chooses one run's setting: it cannot be held with --compare");
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
  if (commands_.size() < 64) commands_.push_back(std::move(c));  // a flood of commands is cut, not queued
  commands_changed_.notify_all();
}

void LiveRun::check_scene(const std::string& name) const {
  RunOptions o = options_;
  o.scene = name;
  const Scene scene = load_scene(name, scene_overrides(o));
  check_run_memory(o, scene, derive(scene), device_ ? &*device_ : nullptr, panels_);
}

std::string LiveRun::description() const {
  std::lock_guard lock(frames_mutex_);
  return description_;
}

void LiveRun::describe(std::string about) {
  std::lock_guard lock(frames_mutex_);
  description_ = std::move(about);
}

std::shared_ptr<const LiveFrame> LiveRun::next_frame(uint64_t after, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(frames_mutex_);
  encoded_changed_.wait_for(lock, timeout, [&] { return stopping_ || (encoded_ && encoded_->number > after); });
  return encoded_ && encoded_->number > after ? encoded_ : nullptr;
}

// The run's thread: the Vulkan device, the solvers and the GL context live here.
void LiveRun::simulate(const LiveOptions& o, std::promise<void>& ready) {
  std::unique_ptr<vk::Context> ctx;
  Stage stage;
  try {
    ctx = make_context(o.run.device, o.run.validate);
    if (ctx) device_ = ctx->info();
    check_scene(o.run.scene);
    stage.load(o.run, o.compare, ctx.get());
    fps_ = stage.scene.fps;  // before the encoder's thread starts, which reads it
    describe(stage.about());
    ready.set_value();
  } catch (...) {
    ready.set_exception(std::current_exception());
    return;
  }
  try {
    run_frames(stage, ctx.get(), o.frame_budget_ms);
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

// The speed-accuracy front from where the run is: each candidate setting run for a few frames
// from the first lane's particles now (one frame first, unmeasured, for its first-use costs),
// then the run goes on from those particles under the setting it had. The renderer is let go
// while it measures.
std::vector<FrontPoint> LiveRun::measure_front(Stage& stage, const vk::Context* ctx) {
  constexpr int kTrialFrames = 6;
  const ParticleState now = stage.lanes[0].solver->download();
  const LiveSetting was = stage.lanes[0].setting;
  const Camera camera = stage.capture->camera();
  const bool smoothed = stage.capture->draws_surface();  // a live frame's cost includes them
  const bool white_water = stage.capture->draws_white_water();
  stage.capture.reset();
  std::vector<FrontPoint> measured;
  for (const LiveSetting& candidate : budget_candidates(stage.scene_substeps)) {
    if (stopping_) break;
    stage.make_first(candidate, ctx);
    Solver& solver = *stage.lanes[0].solver;
    solver.set_smoothed_positions(smoothed);
    solver.set_white_water(white_water);
    solver.upload(now);
    solver.advance(candidate.substeps);
    FrontPoint p{stage.lanes[0].setting};
    const Clock::time_point began = Clock::now();
    for (int frame = 0; frame < kTrialFrames; ++frame)
      p.mean_compression += solver.advance(candidate.substeps).mean_compression / kTrialFrames;
    p.simulate_ms = ms_since(began) / kTrialFrames;
    measured.push_back(p);
  }
  stage.make_first(was, ctx);
  stage.lanes[0].solver->upload(now);
  stage.draw_anew(ctx, camera);
  return measured;
}

// The frames, at the scene's clock, and the viewers' commands between them. A frame is due a
// period after the last; one that is late is drawn at once and the clock starts again from it
// (the run then goes as fast as it can).
void LiveRun::run_frames(Stage& stage, const vk::Context* ctx, double budget_ms) {
  auto period = [&] {
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / stage.scene.fps));
  };
  RealtimeFactor realtime;
  uint64_t number = 0;
  double sim_time = 0, other_ms = 0;
  bool paused = false, first = true;
  std::optional<FrameBudget> budget;
  std::shared_ptr<const std::vector<FrontPoint>> front;
  // The budget held from here: the front measured where the run is, its first choice taken.
  auto hold_budget = [&](double ms) {
    budget.reset();
    front.reset();
    if (ms <= 0) return;
    if (other_ms == 0) {  // no frame drawn yet: the first choice needs what drawing costs
      const Clock::time_point began = Clock::now();
      stage.capture->draw(stage.solvers());
      other_ms = ms_since(began);
    }
    budget.emplace(ms, measure_front(stage, ctx), stage.lanes[0].setting);
    front = std::make_shared<const std::vector<FrontPoint>>(budget->front());
    if (const std::optional<LiveSetting> chosen = budget->decide_now(other_ms)) stage.change_setting(*chosen, ctx);
  };
  hold_budget(budget_ms);
  Clock::time_point due = Clock::now();
  while (!stopping_) {
    bool step = false, redraw = false;
    std::optional<LiveSetting> setting;
    std::optional<std::string> style, scene;
    std::optional<double> new_budget;
    {
      std::unique_lock lock(commands_mutex_);
      if (paused && commands_.empty()) commands_changed_.wait_for(lock, std::chrono::milliseconds(100));
      for (; !commands_.empty(); commands_.pop_front()) {
        const LiveCommand& c = commands_.front();
        switch (c.kind) {
          case LiveCommand::Kind::Pause: paused = true; break;
          case LiveCommand::Kind::Resume: paused = false; break;
          case LiveCommand::Kind::Step: step = paused = true; break;
          case LiveCommand::Kind::Restart:
            for (Lane& lane : stage.lanes) lane.solver->upload(stage.start);
            sim_time = 0, first = true;
            break;
          case LiveCommand::Kind::Setting: setting = c.setting, redraw = true; break;
          case LiveCommand::Kind::Style: style = c.style, redraw = true; break;
          case LiveCommand::Kind::Camera: stage.capture->set_camera(moved(stage.capture->camera(), c)), redraw = true; break;
          case LiveCommand::Kind::Scene: scene = c.scene; break;
          case LiveCommand::Kind::Budget: new_budget = c.budget_ms; break;
        }
      }
    }
    if (stopping_) break;
    if (scene) {  // the new scene's start, under the settings the run has (a held budget measures it anew)
      std::vector<LiveSetting> settings;  // at the new scene's own substeps
      for (const Lane& lane : stage.lanes) settings.push_back({lane.setting.method, lane.setting.iterations, 0});
      RunOptions o = stage.options;
      o.scene = *scene;
      stage.load(o, settings, ctx);
      fps_ = stage.scene.fps;
      sim_time = 0, first = true;
      if (budget && !new_budget) new_budget = budget->budget_ms();
    }
    if (setting) {  // the viewer's choice, at the scene's substeps: a budget held gives it back
      stage.change_setting(*setting, ctx);
      budget.reset(), front.reset();
    }
    if (style) {
      stage.options.style = *style;
      stage.draw_anew(ctx, stage.capture->camera());
    }
    if (new_budget) hold_budget(*new_budget);
    if (scene || setting || new_budget) describe(stage.about());
    if (paused && !step && !first && !redraw && !scene) {
      realtime.restart();
      due = Clock::now();
      continue;
    }
    const bool advance = !first && (!paused || step);
    auto frame = std::make_shared<LiveFrame>();
    const Clock::time_point began = Clock::now();
    for (const Lane& lane : stage.lanes)
      frame->panels.push_back({lane.setting, lane.solver->advance(advance ? lane.setting.substeps : 0)});  // 0: measures only
    frame->simulate_ms = ms_since(began);
    if (advance) sim_time += 1.0 / stage.scene.fps;
    realtime.add(advance ? 1.0 / stage.scene.fps : 0.0);
    first = false;
    frame->number = ++number;
    frame->sim_time = sim_time;
    frame->realtime_factor = paused ? 0.0 : realtime.value();
    frame->paused = paused;
    frame->scene = stage.scene.name;
    frame->about = description();
    frame->budget_ms = budget ? budget->budget_ms() : 0;
    frame->front = front;
    const Clock::time_point simulated = Clock::now();
    auto image = std::make_shared<const capture::Image>(stage.capture->draw(stage.solvers()));
    frame->draw_ms = ms_since(simulated);
    other_ms = frame->draw_ms;
    frame->drawn_unix_ms =
        std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch()).count();
    if (budget && advance) {
      budget->add(frame->simulate_ms, frame->draw_ms);
      if (const std::optional<LiveSetting> chosen = budget->decide()) {
        stage.change_setting(*chosen, ctx);
        describe(stage.about());
      }
    }
    {
      std::lock_guard lock(frames_mutex_);  // the encoder takes the newest; one it missed is dropped
      drawn_ = std::move(frame);
      drawn_image_ = std::move(image);
      drawn_changed_.notify_all();
    }
    due += period();
    const Clock::time_point now = Clock::now();
    if (now < due) std::this_thread::sleep_until(due);
    else if (now - due > period()) due = now;  // behind: as fast as it can, the clock from here
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
                                                        std::max(1, int(std::lround(fps_.load()))), rate);
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
