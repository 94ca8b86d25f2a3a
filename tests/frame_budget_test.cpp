// The frame budget's rule (app/frame_budget.hpp): the front it keeps from what it measured,
// the setting it takes for a budget, and when it changes its mind.
#include <gtest/gtest.h>

#include "app/frame_budget.hpp"
#include "common/input_error.hpp"

namespace pbflow {
namespace {

LiveSetting pbf(int iterations, int substeps = 2) { return {"pbf", iterations, substeps}; }

// Four PBF settings dearer and more accurate in turn, and an LDC one that a cheaper PBF beats.
std::vector<FrontPoint> measured() {
  return {{pbf(1), 10, 0.004}, {pbf(2), 14, 0.002}, {{"ldc", 1, 2}, 15, 0.003}, {pbf(3), 18, 0.0015},
          {pbf(4), 22, 0.001}};
}

TEST(FrameBudget, TheFrontKeepsWhatNothingBeatsCheapestFirst) {
  const std::vector<FrontPoint> front = speed_accuracy_front(measured());
  ASSERT_EQ(front.size(), 4u);  // ldc@1 costs more than pbf@2 and holds less
  for (size_t i = 1; i < front.size(); ++i) {
    EXPECT_GT(front[i].simulate_ms, front[i - 1].simulate_ms);
    EXPECT_LT(front[i].mean_compression, front[i - 1].mean_compression);
  }
  EXPECT_EQ(front.front().setting, pbf(1));
  EXPECT_EQ(front.back().setting, pbf(4));
}

TEST(FrameBudget, TakesTheMostAccurateSettingThatFits) {
  const FrameBudget budget(20, measured(), pbf(4));  // from the dearest: no headroom asked to go down
  EXPECT_EQ(budget.choose(1.0, 0), pbf(3));          // 18 fits 20, 22 does not
  EXPECT_EQ(budget.choose(1.0, 5), pbf(2));          // the drawing's 5 ms counts: 14 + 5
  EXPECT_EQ(budget.choose(2.0, 0), pbf(1));          // the state costs twice what was measured: 2 x 10
  EXPECT_EQ(budget.choose(3.0, 0), pbf(1));          // nothing fits: the cheapest
  EXPECT_EQ(FrameBudget(1000, measured(), pbf(1)).choose(1.0, 0), pbf(4));  // room for all: the most accurate
}

TEST(FrameBudget, GoesDearerOnlyWithHeadroom) {
  // From pbf@2, pbf@3 (18 ms) is taken only within 80 % of the budget: 18 <= 18 at 22.5, not at 22.
  EXPECT_EQ(FrameBudget(22.5, measured(), pbf(2)).choose(1.0, 0), pbf(3));
  EXPECT_EQ(FrameBudget(22, measured(), pbf(2)).choose(1.0, 0), pbf(2));
  // Staying costs no headroom: pbf@3 holds at 22 once taken.
  EXPECT_EQ(FrameBudget(22, measured(), pbf(3)).choose(1.0, 0), pbf(3));
}

TEST(FrameBudget, DecidesOnceASecondFromWhatTheFramesCost) {
  using Clock = FrameBudget::Clock;
  FrameBudget budget(20, measured(), pbf(3));
  const Clock::time_point start = Clock::now();
  budget.add(36, 0);  // pbf@3 costs twice its 18 ms now
  EXPECT_FALSE(budget.decide(start + std::chrono::milliseconds(500)));  // within the second: no change
  const std::optional<LiveSetting> chosen = budget.decide(start + std::chrono::milliseconds(1500));
  ASSERT_TRUE(chosen);
  EXPECT_EQ(*chosen, pbf(1));  // at twice the cost only pbf@1's 10 ms fits
  EXPECT_EQ(budget.current(), pbf(1));
  budget.add(10, 0);  // as measured again: pbf@2 fits within the headroom (14 <= 16), pbf@3 not
  EXPECT_EQ(budget.decide(start + std::chrono::milliseconds(3000)), pbf(2));
  EXPECT_FALSE(budget.decide(start + std::chrono::milliseconds(4500)));  // no frame since: no evidence, no change
}

TEST(FrameBudget, CandidatesAreTheSceneSubstepsAndTwice) {
  const std::vector<LiveSetting> all = budget_candidates(3);
  ASSERT_FALSE(all.empty());
  for (const LiveSetting& s : all) EXPECT_TRUE(s.substeps == 3 || s.substeps == 6) << s.name();
}

TEST(FrameBudget, SettingsParseOrSayWhy) {
  EXPECT_EQ(parse_live_setting("ldc@3"), (LiveSetting{"ldc", 3, 0}));
  for (const char* bad : {"pbf", "pbf@", "pbf@0", "pbf@17", "pbf@2x", "sph@2", "@2", "pbf@-1", "pbf@ 2"})
    EXPECT_THROW(parse_live_setting(bad), InputError) << bad;
}

}  // namespace
}  // namespace pbflow
