#include "app/live_run.hpp"

#include <algorithm>
#include <cmath>
#include <future>
#include <iostream>
#include <numbers>
#include <sstream>

#include "capture/frame_capture.hpp"
#include "capture/stream/h264.hpp"
#include "capture/stream/jpeg.hpp"
#include "gpu/make_solver.hpp"
#include "scene/derive.hpp"
#include "scene/framing.hpp"
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

// `scene` under `s`: its method and iterations, and its substeps where `s` names them (a
// setting is checked where it comes in: parse_live_setting, the server's command).
Scene with_setting(Scene scene, const LiveSetting& s) {
  scene.solver.method = parse_method(s.method);
  scene.solver.iterations = s.iterations;
  scene.solver.max_iterations = std::max(scene.solver.max_iterations, s.iterations);
  if (s.substeps > 0) scene.solver.substeps = s.substeps;
  return scene;
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

// The shift from where the scene places obstacle k that puts its middle nearest `position`
// with its bounds inside the domain: a box may touch a wall (the projection keeps it sound
// there, sim/solids/obstacles.hpp), a sphere or a mesh keeps two spacings off it unless the scene
// put it nearer.
glm::dvec3 hand_shift(const Scene& scene, size_t k, const glm::dvec3& position) {
  const Obstacle& o = scene.obstacles[k];
  const glm::dvec3 lo = o.low(), hi = o.high();
  const double gap = o.kind == Obstacle::Kind::Box ? 0.0 : 2.0 * scene.particle_spacing;
  const glm::dvec3 least = glm::min(scene.domain.min + gap - lo, glm::dvec3(0.0)),
                   most = glm::max(scene.domain.max - gap - hi, glm::dvec3(0.0));
  return glm::clamp(position - o.middle(), least, most);
}

// The period of the tank's first sloshing mode along `axis` (linear waves: w^2 = g k tanh(k d),
// k = pi / L), d the fluid's mean depth: where a shake with no period is felt most.
double sloshing_period(const Scene& scene, const glm::dvec3& axis) {
  const glm::dvec3 size = scene.domain.max - scene.domain.min;
  const double length = glm::dot(glm::abs(axis), size), g = glm::length(scene.gravity);
  const double depth = std::min(fluid_volume(scene) / (size.x * size.z), size.y), k = std::numbers::pi / length;
  return g > 0 ? 2 * std::numbers::pi / std::sqrt(g * k * std::tanh(k * depth)) : 1.0;
}

// The obstacles as the first panel's camera sees them, placed by `poses` in the tank placed by
// `tank` (LiveSolid).
std::vector<LiveSolid> seen_solids(const Scene& scene, const Pose& tank, const std::vector<Pose>& poses,
                                   const Camera& camera, double aspect) {
  const capture::CameraAxes axes = capture::camera_axes(camera);
  std::vector<LiveSolid> seen;
  for (size_t k = 0; k < scene.obstacles.size() && k < poses.size(); ++k) {
    LiveSolid s;
    s.centre = tank.world(poses[k].world(scene.obstacles[k].middle()));
    s.body = scene.obstacles[k].body >= 0;
    const glm::dvec3 p = s.centre - camera.eye;
    const double depth = glm::dot(p, axes.forward);
    if (depth > 0 && !scene.obstacles[k].container) {  // the domain's mesh is not for dragging
      s.span = 2 * depth * std::tan(glm::radians(camera.fov_degrees) / 2);
      s.screen = {0.5 + glm::dot(p, axes.right) / (s.span * aspect), 0.5 - glm::dot(p, axes.up) / s.span};
      s.radius = scene.obstacles[k].extent() / s.span;
    }
    seen.push_back(s);
  }
  return seen;
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
  Scene base;          // the scene as loaded, under no setting
  Scene scene;         // the first lane's
  int scene_substeps = 1;  // the scene's own, before any setting: the frame budget's base
  std::vector<Lane> lanes;
  ParticleState start;  // relaxed and, for a tank, settled: every lane starts and restarts here
  SolidsState start_solids;  // the solids where the scene places them, still, at time 0
  Motion shake;              // the tank's live shaking, as the viewers last asked
  LiveTilt tilt;             // and its tilt
  bool emitting = true;      // the scene's emitters, as the viewers last switched them
  // Whether the lanes' solvers are made for a viewer's hand (Derived::steerable): not until a
  // viewer first drags, shakes or tilts, since the poses compiled in cost a still box scene 1.36x on lavapipe.
  bool steerable = false;
  std::unique_ptr<capture::FrameCapture> capture;
  std::function<void(const std::string&)> before_load;  // LiveOptions::before_load

  std::vector<const Solver*> solvers() const {
    std::vector<const Solver*> all;
    for (const Lane& lane : lanes) all.push_back(lane.solver.get());
    return all;
  }
  // The lanes of `loaded` (o.scene), one a setting (none given: the scene's own), from the
  // first's relaxed start, and their renderer: what a run starts with and a new scene brings.
  void load(const RunOptions& o, const Scene& loaded, const std::vector<LiveSetting>& settings, const vk::Context* ctx) {
    capture.reset();
    lanes.clear();
    options = o;
    base = loaded;
    scene_substeps = base.solver.substeps;
    steerable = false;
    if (before_load) before_load(o.scene);
    for (const LiveSetting& s : settings.empty() ? std::vector<LiveSetting>{setting_of(base)} : settings) {
      const Scene lane = with_setting(base, s);
      if (lanes.empty()) scene = lane;
      lanes.push_back(make_lane(lane, ctx, false));
    }
    Solver& first = *lanes[0].solver;
    relax_start(first);
    if (scene.settle) settle(first, derive(scene));
    start = first.download();
    start_solids = first.solids();
    shake = {}, tilt = {}, emitting = true;
    for (Lane& lane : lanes) lane.solver->upload(start);
    // A view the scene left to framing fits every tilt a viewer may ask.
    draw_anew(ctx, scene.camera_framed ? framing_camera(scene, kMaxTiltDegrees) : scene.camera);
  }
  // Every lane back at the start, the solids too.
  void restart() {
    for (Lane& lane : lanes) lane.solver->upload(start), lane.solver->carry(start_solids);
    shake = {}, tilt = {}, emitting = true;
  }
  // What the run is, to go back to where a viewer's change fails half way.
  struct Saved {
    RunOptions options;
    Scene base, scene;
    int scene_substeps;
    std::vector<LiveSetting> settings;  // substeps resolved
    std::vector<ParticleState> now;     // each lane's
    std::vector<SolidsState> solids;    // each lane's
    ParticleState start;
    SolidsState start_solids;
    Motion shake;
    LiveTilt tilt;
    bool steerable;
    Camera camera;
  };
  Saved save() const {
    Saved s{options, base, scene, scene_substeps, {}, {}, {}, start, start_solids, shake, tilt, steerable,
            capture->camera()};
    for (const Lane& lane : lanes) {
      s.settings.push_back(lane.setting), s.now.push_back(lane.solver->download());
      s.solids.push_back(lane.solver->solids());
    }
    return s;
  }
  void restore(const Saved& s, const vk::Context* ctx) {
    capture.reset();
    lanes.clear();  // before the old are made again: one run's memory at a time
    options = s.options, base = s.base, scene = s.scene, scene_substeps = s.scene_substeps, start = s.start;
    start_solids = s.start_solids, shake = s.shake, tilt = s.tilt, steerable = s.steerable;
    for (size_t i = 0; i < s.settings.size(); ++i) {
      lanes.push_back(make_lane(with_setting(base, s.settings[i]), ctx, steerable));
      lanes.back().solver->upload(s.now[i]);
      lanes.back().solver->carry(s.solids[i]);
    }
    draw_anew(ctx, s.camera);
  }
  // The first lane under another setting, its particles and solids carried over.
  void change_setting(const LiveSetting& s, const vk::Context* ctx) {
    const Camera camera = capture->camera();
    capture.reset();
    scene = with_setting(base, s);
    remake(lanes[0], s, ctx);
    draw_anew(ctx, camera);
  }
  // `lane`'s solver made anew under `s`, its particles and solids carried over; the renderer,
  // which shares its buffers, must be gone.
  void remake(Lane& lane, LiveSetting s, const vk::Context* ctx) {  // by value: it may be the lane's own
    const ParticleState now = lane.solver->download();
    const SolidsState solids = lane.solver->solids();
    lane.solver.reset();  // before the next is made: one solver's memory at a time
    lane = make_lane(with_setting(base, s), ctx, steerable);
    lane.solver->upload(now);
    lane.solver->carry(solids);
  }
  // The first lane's solver made anew under `s`, at the scene's start; the renderer, which
  // shares its buffers, must be gone.
  void make_first(const LiveSetting& s, const vk::Context* ctx) {
    scene = with_setting(base, s);
    lanes[0].solver.reset();  // before the next is made: one solver's memory at a time
    lanes[0] = make_lane(scene, ctx, steerable);
  }
  // A lane of `lane`'s setting, its solver at the scene's start; `steerable`: for a viewer's hand.
  static Lane make_lane(const Scene& lane, const vk::Context* ctx, bool steerable) {
    Derived d = derive(lane);
    if (steerable) d.make_steerable();
    return {setting_of(lane), make_solver(ctx, d, initial_particles(lane))};
  }
  // Every lane's solver made anew for a viewer's hand, its particles and solids carried over.
  void make_steerable(const vk::Context* ctx) {
    if (steerable) return;
    const Camera camera = capture->camera();
    capture.reset();
    steerable = true;
    for (Lane& lane : lanes) remake(lane, lane.setting, ctx);
    draw_anew(ctx, camera);
  }
  void draw_anew(const vk::Context* ctx, Camera camera) {  // by value: it may be the old renderer's
    capture.reset();
    capture = make_frame_capture(options, scene, solvers(), ctx);
    capture->set_camera(camera);
    for (Lane& lane : lanes) lane.solver->set_outputs(capture->outputs());
  }
  std::string about() const {
    std::string settings;
    for (const Lane& lane : lanes) settings += (settings.empty() ? "" : " | ") + lane.setting.name();
    return scene.name + ", " + std::to_string(lanes[0].solver->particle_count()) + " particles, " + settings + ", " +
           std::to_string(scene.solver.substeps) + " substeps per frame, on " + lanes[0].solver->device_name();
  }
};

// The frame loop's state: the clock, what is shown, the budget held.
struct LiveRun::Pace {
  RealtimeFactor realtime;
  uint64_t number = 0;  // frames drawn
  double sim_time = 0;  // since the last (re)start
  double other_ms = 0;  // a frame's work besides simulating: the last frame's drawing
  bool paused = false, first = true;
  std::optional<FrameBudget> budget;
  std::shared_ptr<const std::vector<FrontPoint>> front;
};

LiveRun::LiveRun(const LiveOptions& options)
    : options_(options.run), panels_(std::max<size_t>(1, options.compare.size())) {
  if (options.compare.size() > kMaxPanels)
    throw InputError("--compare takes at most " + std::to_string(kMaxPanels) + " settings");
  if (int64_t(options.run.width) * int64_t(panels_) > capture::JpegEncoder::kMaxSide)
    throw InputError("--compare draws " + std::to_string(panels_) + " panels of --width " +
                     std::to_string(options.run.width) + " side by side, wider than a JPEG frame's " +
                     std::to_string(capture::JpegEncoder::kMaxSide) + " pixels: lower --width");
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

Scene LiveRun::checked_scene(const RunOptions& o) const {
  Scene scene = load_scene(o.scene, scene_overrides(o));
  check_run_memory(o, scene, derive(scene), device_ ? &*device_ : nullptr, panels_);
  return scene;
}

void LiveRun::check_scene(const std::string& name) const {
  RunOptions o = options_;
  o.scene = name;
  checked_scene(o);
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
    stage.before_load = o.before_load;
    const Scene scene = checked_scene(o.run);
    // The start's relaxation and settle can take a minute on a CPU device: say so before them.
    std::cerr << "pbflow: setting up " << scene.name << ": relaxing" << (scene.settle ? " and settling" : "")
              << " its start\n";
    stage.load(o.run, scene, o.compare, ctx.get());
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
  const SolidsState solids = stage.lanes[0].solver->solids();
  const LiveSetting was = stage.lanes[0].setting;
  const Camera camera = stage.capture->camera();
  const FrameOutputs outputs = stage.capture->outputs();  // a live frame's cost includes them
  stage.capture.reset();
  std::vector<FrontPoint> measured;
  for (const LiveSetting& candidate : budget_candidates(stage.scene_substeps)) {
    if (stopping_) break;
    stage.make_first(candidate, ctx);
    Solver& solver = *stage.lanes[0].solver;
    solver.set_outputs(outputs);
    solver.upload(now);
    solver.carry(solids);
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
  stage.lanes[0].solver->carry(solids);
  stage.draw_anew(ctx, camera);
  return measured;
}

// What the viewers asked since the last frame, taken at once: the newest of each kind.
struct LiveRun::Asked {
  bool step = false, redraw = false, restart = false;
  std::optional<bool> paused;
  std::optional<LiveCommand> setting, style, scene, budget, shake, tilt, emit;
  std::vector<LiveCommand> cameras, drags;
};

// The frames, at the scene's clock, and the viewers' commands between them. A frame is due a
// period after the last; one that is late is drawn at once and the clock starts again from it
// (the run then goes as fast as it can). The wait for the next frame ends at once for a command
// or a stop, so that a low fps holds up neither.
void LiveRun::run_frames(Stage& stage, const vk::Context* ctx, double budget_ms) {
  auto period = [&] {
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / stage.scene.fps));
  };
  Pace pace;
  hold_budget(stage, ctx, pace, budget_ms);
  Clock::time_point due = Clock::now();
  while (!stopping_) {
    Asked asked = take_commands(pace.paused ? Clock::now() + std::chrono::milliseconds(100) : due);
    if (stopping_) break;
    if (asked.paused) pace.paused = *asked.paused;
    if (asked.restart) {
      stage.restart();
      pace.sim_time = 0, pace.first = true;
    }
    const bool changed = apply(stage, ctx, pace, asked);
    const Clock::time_point now = Clock::now();
    if (pace.paused && !asked.step && !pace.first && !asked.redraw && !changed) {
      pace.realtime.restart();
      due = now;
      continue;
    }
    const bool advance = !pace.first && (pace.paused ? asked.step : now >= due);
    if (!advance && !pace.first && !asked.redraw && !changed) continue;  // not due yet, nothing to show
    draw_frame(stage, ctx, pace, advance);
    if (!advance) continue;
    due += period();
    if (Clock::now() - due > period()) due = Clock::now();  // behind: as fast as it can, the clock from here
  }
}

LiveRun::Asked LiveRun::take_commands(Clock::time_point until) {
  Asked asked;
  std::unique_lock lock(commands_mutex_);
  commands_changed_.wait_until(lock, until, [&] { return stopping_ || !commands_.empty(); });
  for (; !commands_.empty(); commands_.pop_front()) {
    LiveCommand& c = commands_.front();
    switch (c.kind) {
      case LiveCommand::Kind::Pause: asked.paused = true; break;
      case LiveCommand::Kind::Resume: asked.paused = false; break;
      case LiveCommand::Kind::Step: asked.step = true, asked.paused = true; break;
      case LiveCommand::Kind::Restart: asked.restart = true; break;
      case LiveCommand::Kind::Setting: asked.setting = std::move(c), asked.redraw = true; break;
      case LiveCommand::Kind::Style: asked.style = std::move(c), asked.redraw = true; break;
      case LiveCommand::Kind::Camera: asked.cameras.push_back(std::move(c)), asked.redraw = true; break;
      case LiveCommand::Kind::Scene: asked.scene = std::move(c); break;
      case LiveCommand::Kind::Budget: asked.budget = std::move(c); break;
      case LiveCommand::Kind::Drag: asked.drags.push_back(std::move(c)); break;
      case LiveCommand::Kind::Shake: asked.shake = std::move(c); break;
      case LiveCommand::Kind::Tilt: asked.tilt = std::move(c); break;
      case LiveCommand::Kind::Emit: asked.emit = std::move(c); break;
    }
  }
  return asked;
}

// The viewers' changes, each whole or not at all: one the run cannot take (a scene that fails
// to load) is undone, the run goes on as it was and the viewer who asked is told. Returns
// whether the scene, setting or budget changed.
bool LiveRun::apply(Stage& stage, const vk::Context* ctx, Pace& pace, Asked& asked) {
  for (const LiveCommand& c : asked.cameras) stage.capture->set_camera(moved(stage.capture->camera(), c));
  auto attempt = [&](const std::optional<LiveCommand>& c, const std::function<void()>& change) {
    if (!c) return false;
    const Stage::Saved saved = stage.save();
    try {
      change();
      return true;
    } catch (const std::exception& e) {
      stage.restore(saved, ctx);  // where this fails too the run stops, as it must
      if (c->refused) c->refused(e.what());
      return false;
    }
  };
  // A viewer's first hand on the solids makes the lanes steerable (Stage::make_steerable), or is refused.
  const std::optional<LiveCommand> hand =
      !asked.drags.empty() ? std::optional(asked.drags.front()) : asked.shake ? asked.shake : asked.tilt;
  if (hand && (stage.steerable || attempt(hand, [&] { stage.make_steerable(ctx); }))) steer(stage, asked);
  if (asked.emit && stage.scene.emitters.empty()) {
    if (asked.emit->refused) asked.emit->refused("the scene has no emitters");
  } else if (asked.emit) {
    stage.emitting = asked.emit->emitting;
  }
  std::optional<double> new_budget = asked.budget ? std::optional<double>(asked.budget->budget_ms) : std::nullopt;
  const bool scene = attempt(asked.scene, [&] {  // the new scene's start, under the settings the run has
    std::vector<LiveSetting> settings;            // at the new scene's own substeps
    for (const Lane& lane : stage.lanes) settings.push_back({lane.setting.method, lane.setting.iterations, 0});
    RunOptions o = stage.options;
    o.scene = asked.scene->scene;
    stage.load(o, checked_scene(o), settings, ctx);
  });
  if (scene) {
    fps_ = stage.scene.fps;
    pace.sim_time = 0, pace.first = true;
    if (pace.budget && !new_budget) new_budget = pace.budget->budget_ms();  // measured anew
  }
  const bool setting = attempt(asked.setting, [&] { stage.change_setting(asked.setting->setting, ctx); });
  if (setting) pace.budget.reset(), pace.front.reset();  // the viewer's choice: a budget held gives it back
  attempt(asked.style, [&] {
    stage.options.style = asked.style->style;
    stage.draw_anew(ctx, stage.capture->camera());
  });
  const bool budget = new_budget && attempt(asked.budget ? asked.budget : asked.scene, [&] {
    hold_budget(stage, ctx, pace, *new_budget);
  });
  if (scene || setting || budget) describe(stage.about());
  return scene || setting || budget;
}

// A viewer's hand on the solids, in every lane: drags (each obstacle's newest wins), the tank's
// tilt and its shaking. One the scene cannot take is refused, naming why.
void LiveRun::steer(Stage& stage, const Asked& asked) {
  for (const LiveCommand& c : asked.drags) {
    if (c.obstacle >= stage.scene.obstacles.size()) {
      if (c.refused) c.refused("the scene has " + std::to_string(stage.scene.obstacles.size()) + " obstacle(s)");
      continue;
    }
    if (stage.scene.obstacles[c.obstacle].container) {
      if (c.refused) c.refused("obstacle " + std::to_string(c.obstacle) + " is the domain's mesh: shake the tank instead");
      continue;
    }
    if (c.release) {
      for (Lane& lane : stage.lanes) lane.solver->release(c.obstacle);
      continue;
    }
    // The page's point is in the world, the solids in the tank's frame.
    const glm::dvec3 shift = hand_shift(stage.scene, c.obstacle, stage.lanes[0].solver->tank_pose().body(c.position));
    for (Lane& lane : stage.lanes) lane.solver->drag(c.obstacle, shift);
  }
  if (asked.tilt) {
    stage.tilt = asked.tilt->tilt;
    for (Lane& lane : stage.lanes) lane.solver->tilt(glm::angleAxis(glm::radians(stage.tilt.degrees), stage.tilt.axis));
  }
  if (!asked.shake) return;
  const LiveCommand& c = *asked.shake;
  Motion m;
  if (c.amplitude > 0) {
    m.type = Motion::Type::Oscillate, m.axis = c.axis, m.amplitude = c.amplitude;
    m.period = c.period > 0 ? c.period : sloshing_period(stage.scene, c.axis);
  }
  const double most = kSolidStep * stage.scene.particle_spacing * stage.scene.fps * stage.scene_substeps;
  if (m.moves() && m.top_speed(0) > most) {
    std::ostringstream why;
    why << "the tank would move at " << m.top_speed(0) << " m/s, faster than " << most
        << " m/s (half a spacing a step): lower the amplitude or lengthen the period";
    if (c.refused) c.refused(why.str());
    return;
  }
  stage.shake = m;
  for (Lane& lane : stage.lanes) lane.solver->shake(m);
}

// The budget held from here: the front measured where the run is, its first choice taken.
void LiveRun::hold_budget(Stage& stage, const vk::Context* ctx, Pace& pace, double ms) {
  pace.budget.reset();
  pace.front.reset();
  if (ms <= 0) return;
  if (pace.other_ms == 0) {  // no frame drawn yet: the first choice needs what drawing costs
    const Clock::time_point began = Clock::now();
    stage.capture->draw(stage.solvers());
    pace.other_ms = ms_since(began);
  }
  pace.budget.emplace(ms, measure_front(stage, ctx), stage.lanes[0].setting);
  pace.front = std::make_shared<const std::vector<FrontPoint>>(pace.budget->front());
  if (const std::optional<LiveSetting> chosen = pace.budget->decide_now(pace.other_ms))
    stage.change_setting(*chosen, ctx);
}

// One frame: the lanes advanced a frame (or measured only), drawn, and handed to the encoder.
void LiveRun::draw_frame(Stage& stage, const vk::Context* ctx, Pace& pace, bool advance) {
  auto frame = std::make_shared<LiveFrame>();
  const Clock::time_point began = Clock::now();
  for (const Lane& lane : stage.lanes) {
    lane.solver->set_emitting(stage.emitting);  // also a lane made anew since (a setting, a restore)
    frame->panels.push_back({lane.setting, lane.solver->advance(advance ? lane.setting.substeps : 0)});  // 0: measures only
  }
  frame->simulate_ms = ms_since(began);
  if (advance) pace.sim_time += 1.0 / stage.scene.fps;
  pace.realtime.add(advance ? 1.0 / stage.scene.fps : 0.0);
  pace.first = false;
  frame->number = ++pace.number;
  frame->sim_time = pace.sim_time;
  frame->realtime_factor = pace.paused ? 0.0 : pace.realtime.value();
  frame->paused = pace.paused;
  frame->scene = stage.scene.name;
  frame->about = description();
  frame->budget_ms = pace.budget ? pace.budget->budget_ms() : 0;
  frame->front = pace.front;
  const Camera& camera = stage.capture->camera();
  const Solver& first = *stage.lanes[0].solver;
  frame->solids = seen_solids(stage.scene, first.tank_pose(), first.obstacle_poses(), camera,
                              double(stage.options.width) / double(stage.options.height));
  const capture::CameraAxes axes = capture::camera_axes(camera);
  frame->right = axes.right, frame->up = axes.up;
  frame->shake = stage.shake;
  frame->tilt = stage.tilt;
  frame->emitters = stage.scene.emitters.size(), frame->emitting = stage.emitting;
  const Clock::time_point simulated = Clock::now();
  auto image = std::make_shared<const capture::Image>(stage.capture->draw(stage.solvers()));
  frame->draw_ms = ms_since(simulated);
  pace.other_ms = frame->draw_ms;
  frame->drawn_unix_ms =
      std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch()).count();
  if (pace.budget && advance) {
    pace.budget->add(frame->simulate_ms, frame->draw_ms);
    if (const std::optional<LiveSetting> chosen = pace.budget->decide()) {
      stage.change_setting(*chosen, ctx);
      describe(stage.about());
    }
  }
  std::lock_guard lock(frames_mutex_);  // the encoder takes the newest; one it missed is dropped
  drawn_ = std::move(frame);
  drawn_image_ = std::move(image);
  drawn_changed_.notify_all();
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
