// The live run behind `pbflow serve` (app/live_run.hpp): a change a viewer asks for that the run
// cannot take is undone, the viewer is told, and the run goes on as it was.
#include <gtest/gtest.h>

#include <future>
#include <stdexcept>

#include "app/live_run.hpp"

namespace pbflow {
namespace {

using namespace std::chrono_literals;

LiveOptions small_run() {
  LiveOptions o;
  o.run.scene = "hydrostatic";
  o.run.params = {"particle_spacing=0.05"};
  o.run.style = "particles";
  o.run.width = 160, o.run.height = 96;
  o.run.validate = true;
  // What a device that runs out of memory making the drop's solver does.
  o.before_load = [](const std::string& scene) {
    if (scene == "drop") throw std::runtime_error("out of device memory (made by the test)");
  };
  return o;
}

// The first frame after `after` that `predicate` holds, within `limit` frames.
template <typename Predicate>
std::shared_ptr<const LiveFrame> frame_where(const LiveRun& run, uint64_t after, Predicate predicate, int limit = 300) {
  for (int i = 0; i < limit; ++i) {
    std::shared_ptr<const LiveFrame> frame = run.next_frame(after, 30s);
    if (!frame) return nullptr;
    if (predicate(*frame)) return frame;
    after = frame->number;
  }
  return nullptr;
}

TEST(LiveRun, ASceneThatFailsToLoadIsUndoneToldAndTheRunGoesOn) {
  LiveRun run(small_run());
  const auto before = frame_where(run, 0, [](const LiveFrame& f) { return f.sim_time > 0.1; });
  ASSERT_TRUE(before);

  std::promise<std::string> told;
  LiveCommand failing{LiveCommand::Kind::Scene};
  failing.scene = "drop";
  failing.refused = [&](const std::string& why) { told.set_value(why); };
  run.command(failing);
  std::future<std::string> why = told.get_future();
  ASSERT_EQ(why.wait_for(60s), std::future_status::ready) << "the viewer was not told";
  EXPECT_NE(why.get().find("out of device memory"), std::string::npos);

  // The run goes on from where it was: the same scene, its clock not restarted.
  const auto after = frame_where(run, before->number, [&](const LiveFrame& f) { return f.sim_time > before->sim_time; });
  ASSERT_TRUE(after) << run.failure();
  EXPECT_EQ(after->scene, "hydrostatic");
  EXPECT_EQ(run.failure(), "");

  LiveCommand good{LiveCommand::Kind::Scene};  // and a scene that loads still does
  good.scene = "dam_break";
  run.command(good);
  ASSERT_TRUE(frame_where(run, after->number, [](const LiveFrame& f) { return f.scene == "dam_break"; }));
  EXPECT_EQ(run.failure(), "");
}

}  // namespace
}  // namespace pbflow
