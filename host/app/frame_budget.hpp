#pragma once
// `--frame-budget MS`: the live run holds a frame within MS milliseconds by choosing its
// accuracy. It measures the speed-accuracy front on the spot (each candidate setting run for
// a few frames from the current state), then each second or so takes the most accurate point
// whose cost, scaled by what the current setting costs now, fits (docs/serve.md, "Holding the
// frame rate").
#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace pbflow {

// A live run's constraint iterations per step at most: past every setting on the front.
inline constexpr int kMaxLiveIterations = 16;

// A live run's solver setting: method, constraint iterations and steps per frame.
struct LiveSetting {
  std::string method = "pbf";  // "pbf" or "ldc"
  int iterations = 2;
  int substeps = 0;  // 0: the scene's
  std::string name() const { return method + "@" + std::to_string(iterations); }  // "pbf@2"
  bool operator==(const LiveSetting&) const = default;
};

// "pbf@2": METHOD@ITERATIONS, the scene's substeps; throws InputError naming the problem.
LiveSetting parse_live_setting(const std::string& text);

// A setting as measured from one state: its frame's simulation (ms, wall clock, waited for)
// and the mean compression it held over the trial.
struct FrontPoint {
  LiveSetting setting;
  double simulate_ms = 0;
  double mean_compression = 0;
};

// The settings tried: PBF at 1 to 4 iterations and LDC at 1 and 2, each at the scene's
// substeps (the fewest pbflow counts sound) and at twice those.
std::vector<LiveSetting> budget_candidates(int scene_substeps);

// The points no other beats in both cost and compression, cheapest (and least accurate) first.
std::vector<FrontPoint> speed_accuracy_front(std::vector<FrontPoint> measured);

class FrameBudget {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr double kDecideSeconds = 1.0;  // how often the setting may change
  // A dearer setting is taken only within this share of the budget: a point's trial cost is
  // noisy by 10-15 % on a busy machine, and a margin below that let the run flip between two
  // neighbours each second (each flip a new solver).
  static constexpr double kHeadroom = 0.8;

  // `measured`: every candidate's trial; `current`: the setting the run has now (one of them).
  FrameBudget(double budget_ms, std::vector<FrontPoint> measured, LiveSetting current);
  double budget_ms() const { return budget_ms_; }
  const std::vector<FrontPoint>& front() const { return front_; }
  const LiveSetting& current() const { return current_; }

  // One frame's wall-clock cost under the current setting: its simulation, and the rest of
  // the frame's work on the run's thread (drawing, reading back).
  void add(double simulate_ms, double other_ms);
  // Once a second: the setting the rule picks where it differs from the current one (which
  // it then becomes), else none. `now` is for tests.
  std::optional<LiveSetting> decide(Clock::time_point now = Clock::now());
  // The first choice, as the front was measured (scale 1), with the rest of a frame's work.
  std::optional<LiveSetting> decide_now(double other_ms);
  // The rule alone: the front's most accurate point whose simulation, scaled by `scale` (what
  // the current setting costs now over what it cost when measured), plus `other_ms` fits the
  // budget, a point dearer than the current one only within kHeadroom of it; where none
  // fits, the cheapest.
  LiveSetting choose(double scale, double other_ms) const;

 private:
  std::optional<LiveSetting> take(const LiveSetting& chosen);  // the chosen one, where it is new
  double measured_ms(const LiveSetting& s) const;              // its trial's simulation; 0 where not tried

  double budget_ms_;
  std::vector<FrontPoint> measured_, front_;
  LiveSetting current_;
  double simulate_sum_ = 0, other_sum_ = 0;
  int frames_ = 0;
  Clock::time_point since_ = Clock::now();
};

}  // namespace pbflow
