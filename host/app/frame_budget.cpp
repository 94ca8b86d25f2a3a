#include "app/frame_budget.hpp"

#include <algorithm>
#include <charconv>

#include "common/input_error.hpp"

namespace pbflow {

LiveSetting parse_live_setting(const std::string& text) {
  const size_t at = text.find('@');
  LiveSetting s;
  s.method = text.substr(0, at);
  if (at == std::string::npos || (s.method != "pbf" && s.method != "ldc"))
    throw InputError("'" + text + "' is not a setting: METHOD@ITERATIONS, e.g. pbf@2 or ldc@1");
  const char* first = text.data() + at + 1;
  const char* last = text.data() + text.size();
  const auto [end, error] = std::from_chars(first, last, s.iterations);
  if (error != std::errc() || end != last || first == last || s.iterations < 1 ||
      s.iterations > kMaxLiveIterations)
    throw InputError("'" + text + "': the iterations after '@' must be a whole number from 1 to " +
                     std::to_string(kMaxLiveIterations));
  return s;
}

std::vector<LiveSetting> budget_candidates(int scene_substeps) {
  std::vector<LiveSetting> all;
  for (int substeps : {scene_substeps, 2 * scene_substeps}) {
    for (int iterations : {1, 2, 3, 4}) all.push_back({"pbf", iterations, substeps});
    for (int iterations : {1, 2}) all.push_back({"ldc", iterations, substeps});
  }
  return all;
}

std::vector<FrontPoint> speed_accuracy_front(std::vector<FrontPoint> measured) {
  std::sort(measured.begin(), measured.end(), [](const FrontPoint& a, const FrontPoint& b) {
    return a.simulate_ms != b.simulate_ms ? a.simulate_ms < b.simulate_ms : a.mean_compression < b.mean_compression;
  });
  std::vector<FrontPoint> front;
  for (const FrontPoint& p : measured)  // dearer than every point kept: worth it only if more accurate
    if (front.empty() || p.mean_compression < front.back().mean_compression) front.push_back(p);
  return front;
}

FrameBudget::FrameBudget(double budget_ms, std::vector<FrontPoint> measured, LiveSetting current)
    : budget_ms_(budget_ms), measured_(std::move(measured)), front_(speed_accuracy_front(measured_)),
      current_(std::move(current)) {}

void FrameBudget::add(double simulate_ms, double other_ms) {
  simulate_sum_ += simulate_ms;
  other_sum_ += other_ms;
  ++frames_;
}

std::optional<LiveSetting> FrameBudget::decide(Clock::time_point now) {
  if (std::chrono::duration<double>(now - since_).count() < kDecideSeconds || frames_ == 0) return std::nullopt;
  const double measured = measured_ms(current_);
  const double simulate_ms = simulate_sum_ / frames_, other_ms = other_sum_ / frames_;
  const double scale = measured > 0 ? std::clamp(simulate_ms / measured, 0.25, 4.0) : 1.0;
  simulate_sum_ = other_sum_ = 0;
  frames_ = 0;
  since_ = now;
  return take(choose(scale, other_ms));
}

std::optional<LiveSetting> FrameBudget::decide_now(double other_ms) { return take(choose(1.0, other_ms)); }

double FrameBudget::measured_ms(const LiveSetting& s) const {
  const auto found = std::find_if(measured_.begin(), measured_.end(), [&](const FrontPoint& p) { return p.setting == s; });
  return found != measured_.end() ? found->simulate_ms : 0;
}

std::optional<LiveSetting> FrameBudget::take(const LiveSetting& chosen) {
  if (chosen == current_) return std::nullopt;
  current_ = chosen;
  return chosen;
}

LiveSetting FrameBudget::choose(double scale, double other_ms) const {
  if (front_.empty()) return current_;
  const double current_ms = measured_ms(current_);
  for (auto p = front_.rbegin(); p != front_.rend(); ++p) {
    const double limit = p->simulate_ms > current_ms ? kHeadroom * budget_ms_ : budget_ms_;
    if (scale * p->simulate_ms + other_ms <= limit) return p->setting;
  }
  return front_.front().setting;
}

}  // namespace pbflow
