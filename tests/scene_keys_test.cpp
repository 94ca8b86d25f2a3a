// The key table (scene/keys.cpp) is the one place a scene key is declared: the parser checks
// every scalar key at its range's edges as the table says, and each default stated once.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "scene/keys.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

// The JSON text of a value just inside or just past a range's edge.
std::string just(double edge, double towards) {
  const double step = std::max(std::abs(edge), 1.0) * 1e-6;
  std::ostringstream s;
  s.precision(17);
  s << edge + (towards > 0 ? step : -step);
  return s.str();
}

TEST(SceneKeys, EveryScalarKeyIsCheckedAtItsRangesEdges) {
  int checked = 0;
  for (const SceneKey& k : scene_keys()) {
    if (!k.range) continue;
    const std::string name(k.name);
    auto parse = [&](const std::string& value) { return load_scene("dam_break", {name + "=" + value}); };
    const KeyRange& r = *k.range;
    const bool whole = k.kind == KeyKind::Whole;
    // Inside: the closed edges themselves (or, open, just inside); a whole key's edges exactly.
    for (auto [edge, open, inward] : {std::tuple{r.lo, r.lo_open, 1.0}, std::tuple{r.hi, r.hi_open, -1.0}}) {
      if (std::isinf(edge)) continue;
      std::ostringstream at;
      at.precision(17);
      at << edge;
      const std::string inside = open ? just(edge, inward) : at.str();
      const std::string outside = whole ? std::to_string((long long)(edge - inward)) : open ? at.str() : just(edge, -inward);
      // A value the solver may still refuse for another reason (an LDC strength past the step's limit,
      // too many particles) is fine inside the range; what matters is that the range check passes it.
      try {
        parse(inside);
      } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()).find(name + " must"), std::string::npos) << name << "=" << inside << ": " << e.what();
      }
      try {
        parse(outside);
        ADD_FAILURE() << name << "=" << outside << " was accepted";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << name << "=" << outside << ": " << e.what();
      }
      ++checked;
    }
  }
  EXPECT_GE(checked, 30);
}

TEST(SceneKeys, EveryKeyOfTheTableIsAcceptedAndNoOther) {
  for (const SceneKey& k : scene_keys()) {
    const std::string name(k.name);
    try {
      load_scene("dam_break", {name + "=null"});
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).find("unknown scene key"), std::string::npos) << name << ": " << e.what();
    }
  }
  EXPECT_THROW(load_scene("dam_break", {"solver.no_such_key=1"}), InputError);
}

// Each default is stated once, in its row: the README points to `pbflow keys` and copies no
// part of the table.
TEST(SceneKeys, TheReadmePointsToTheTableAndCopiesNoRow) {
  std::ifstream readme(std::string(PBFLOW_TEST_DATA) + "/../README.md");
  ASSERT_TRUE(readme) << "README.md not found";
  std::stringstream text;
  text << readme.rdbuf();
  EXPECT_NE(text.str().find("pbflow keys"), std::string::npos);
  for (const SceneKey& k : scene_keys())
    EXPECT_EQ(text.str().find("| `" + std::string(k.name) + "` |"), std::string::npos) << k.name << "'s row is pasted";
}

// A row's default reads as its value, or as the word it states where it has none to read.
TEST(SceneKeys, ADefaultIsShownFromItsValue) {
  for (const SceneKey& k : scene_keys()) {
    const std::string shown = shown_default(k);
    EXPECT_FALSE(shown.empty()) << k.name;
    if (k.value && k.shown.empty() && k.kind == KeyKind::Number) {
      EXPECT_DOUBLE_EQ(std::stod(shown), *k.value) << k.name;
    }
  }
}

}  // namespace
}  // namespace pbflow
