#pragma once
// The live run behind `pbflow serve`: a scene simulated and drawn on its own thread at the
// scene's clock, each frame encoded on another, the newest frame published for any number of
// viewers to take. Nothing a viewer does (or fails to do) makes the simulation wait.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "app/frame_budget.hpp"
#include "app/run.hpp"
#include "capture/renderer.hpp"
#include "vk/context.hpp"

namespace pbflow {

struct LiveOptions {
  RunOptions run;                    // the scene and image options, as `pbflow run` takes them
  std::vector<LiveSetting> compare;  // --compare: these settings side by side from one start; empty: one run
  double frame_budget_ms = 0;        // --frame-budget: hold a frame within this by choosing accuracy; 0: off
  // Called on the run's thread before a scene's solvers are made (the tests make a load fail
  // here: what a device that runs out of memory does); none in a user's run.
  std::function<void(const std::string& scene)> before_load;
};
// At most this many settings side by side.
inline constexpr size_t kMaxPanels = 4;
// The most a viewer may tilt the tank, degrees: enough to run the water of a built-in tank to
// one end; a view the scene leaves to framing fits it (framing_camera).
inline constexpr double kMaxTiltDegrees = 30;

// An obstacle as the page sees it, for dragging it (docs/serve.md): its middle in the world,
// where that lies in the picture (x right, y down, fractions of a panel), its bounding
// sphere's radius there (a fraction of the panel's height) and the metres the panel's height
// spans at its depth; none where it is behind the eye.
struct LiveSolid {
  glm::dvec3 centre{0.0};
  glm::dvec2 screen{0.0};
  double radius = 0, span = 0;
  bool body = false;  // a rigid body: held while dragged, it falls when let go
};

// One panel of a frame: its setting and the measures of its solver.
struct LivePanel {
  LiveSetting setting;  // substeps resolved
  FrameStats stats;
};

// The tank turned `degrees` about `axis` (a unit vector) through its floor's centre, from upright.
struct LiveTilt {
  double degrees = 0;
  glm::dvec3 axis{1, 0, 0};
  bool operator==(const LiveTilt&) const = default;
};

// A frame as viewers get it: the JPEG and the measures it was drawn with.
struct LiveFrame {
  uint64_t number = 0;        // frames drawn since the start (a restart goes on counting)
  double sim_time = 0;        // s of simulated time since the last (re)start
  std::vector<LivePanel> panels;  // one, or one a setting under --compare, left to right
  double realtime_factor = 0;  // simulated over wall seconds, over the last second or so
  bool paused = false;
  std::string scene;          // the scene's name
  std::string about;          // scene, particles, setting, device
  double budget_ms = 0;       // the frame budget held; 0: none
  std::vector<LiveSolid> solids;  // the obstacles as the camera sees them (LiveSolid)
  glm::dvec3 right{1, 0, 0}, up{0, 1, 0};  // the camera's axes in the world: a drag's directions
  Motion shake;               // the tank's live shaking (Type::None: none)
  LiveTilt tilt;              // the tank's live tilt, as the viewers last asked
  size_t emitters = 0;        // the scene's emitters, and whether a viewer left them on
  bool emitting = true;
  std::shared_ptr<const std::vector<FrontPoint>> front;  // the measured front it chooses from, where held
  std::string jpeg;
  // The H.264 stream's access unit for this frame, where some viewer takes H.264: `unit` counts
  // them (a viewer that missed one waits for a keyframe), 0 where there is none.
  std::string h264;
  uint64_t unit = 0;
  bool keyframe = false;
  double drawn_unix_ms = 0;   // when its image was drawn, ms since the Unix epoch (the page's Date.now())
  // The frame's cost on the wall clock: simulating it (its steps, waited for), drawing it and
  // reading it back, encoding it (on the encoder's thread, beside the next frame's work).
  double simulate_ms = 0, draw_ms = 0, encode_ms = 0;
};

// What a viewer can ask of the run (docs/serve.md, "Protocol"), checked by the server.
struct LiveCommand {
  enum class Kind { Pause, Resume, Step, Restart, Setting, Style, Camera, Scene, Budget, Drag, Shake, Tilt, Emit } kind;
  LiveSetting setting;     // Setting: method and iterations (the scene's substeps)
  std::string style;       // Style: a capture::Style's name
  double orbit_x = 0, orbit_y = 0;  // Camera: radians about the up axis and the camera's right
  double zoom = 1;                  // Camera: the eye's distance from the target times this
  double pan_x = 0, pan_y = 0;      // Camera: the target moved by these fractions of that distance
  std::string scene;       // Scene: a built-in scene's name, checked with check_scene()
  double budget_ms = 0;    // Budget: 0 turns it off
  size_t obstacle = 0;     // Drag: the obstacle (scene order) ...
  glm::dvec3 position{0.0};  // ... and where its middle should be, m (kept inside the domain) ...
  bool release = false;      // ... or, for a body, the hand letting it go
  glm::dvec3 axis{1, 0, 0};  // Shake: the direction, a unit vector ...
  double amplitude = 0;      // ... m (0: the tank comes to rest) ...
  double period = 0;         // ... s (0: the tank's first sloshing mode along the axis)
  LiveTilt tilt;             // Tilt: where the tank turns to
  bool emitting = true;      // Emit: the scene's emitters on or off
  // Called on the run's thread where the run could not take it (a scene that failed to load):
  // the run goes on as it was, and whoever asked is told why.
  std::function<void(const std::string& why)> refused;
};

class LiveRun {
 public:
  // Loads the scene, makes the solvers and renderer on the run's thread and starts it; throws
  // InputError (bad scene or options) or the failure that stopped the set-up.
  explicit LiveRun(const LiveOptions& options);
  ~LiveRun();  // stops both threads
  LiveRun(const LiveRun&) = delete;
  LiveRun& operator=(const LiveRun&) = delete;

  void command(LiveCommand c);
  // Whether the built-in scene `name` can take this run's place (its keys, the run's --param
  // entries, the memory it needs): InputError naming the problem where not.
  void check_scene(const std::string& name) const;
  size_t panels() const { return panels_; }  // settings side by side: 1 unless --compare
  // The newest encoded frame past `after` (a frame number), waiting up to `timeout`; null
  // where none came. Returns at once once stop() was called.
  std::shared_ptr<const LiveFrame> next_frame(uint64_t after, std::chrono::milliseconds timeout) const;
  void stop();
  // Viewers taking the H.264 stream: it is encoded while there is one. A viewer that joins or
  // falls behind asks for a keyframe.
  void count_h264_viewer(int delta) { h264_viewers_ += delta; }
  bool h264_available() const { return !h264_broken_; }  // false once the encoder could not start
  // Why the run stopped by itself (a failure on its threads); empty while it runs or was stopped.
  std::string failure() const;
  void request_keyframe() { keyframe_wanted_ = true; }
  std::string description() const;  // scene, particles, setting, device

 private:
  struct Stage;
  struct Pace;
  struct Asked;
  void simulate(const LiveOptions& options, std::promise<void>& ready);
  void run_frames(Stage& stage, const vk::Context* ctx, double budget_ms);
  Asked take_commands(std::chrono::steady_clock::time_point until);
  bool apply(Stage& stage, const vk::Context* ctx, Pace& pace, Asked& asked);
  void steer(Stage& stage, const Asked& asked);
  void hold_budget(Stage& stage, const vk::Context* ctx, Pace& pace, double ms);
  void draw_frame(Stage& stage, const vk::Context* ctx, Pace& pace, bool advance);
  std::vector<FrontPoint> measure_front(Stage& stage, const vk::Context* ctx);
  void encode();
  void encode_frames();
  void fail(const std::string& why);  // a thread's failure: recorded, and the run stops
  // The scene `o` names, loaded once with o's keys and checked against the memory this run has.
  Scene checked_scene(const RunOptions& o) const;
  void describe(std::string about);   // what description() says from here

  const RunOptions options_;  // as given: what check_scene() checks against
  const size_t panels_;
  std::optional<vk::DeviceInfo> device_;  // the solver's; none for the reference solver
  std::atomic<bool> stopping_{false};
  std::atomic<int> h264_viewers_{0};
  std::atomic<bool> keyframe_wanted_{false}, h264_broken_{false};
  std::string failure_, description_;  // under frames_mutex_
  std::atomic<double> fps_{60};  // the scene's: the H.264 stream's rate

  std::mutex commands_mutex_;
  std::condition_variable commands_changed_;
  std::deque<LiveCommand> commands_;

  // The newest drawn frame, waiting for the encoder (its jpeg empty); the newest encoded one.
  mutable std::mutex frames_mutex_;
  mutable std::condition_variable drawn_changed_, encoded_changed_;
  std::shared_ptr<LiveFrame> drawn_;
  std::shared_ptr<const capture::Image> drawn_image_;
  std::shared_ptr<const LiveFrame> encoded_;

  std::thread simulation_, encoder_;
};

}  // namespace pbflow
