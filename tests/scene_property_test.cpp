// Property: no input crashes the scene reader. Every mutation of a built-in scene (values
// nested deep, numbers huge, tiny, negative or past double's range, wrong types, text cut
// short) and every --param value either reads into a scene whose constants can be derived,
// or is refused with InputError. scripts/sanitize.sh runs this under AddressSanitizer and
// UndefinedBehaviorSanitizer; tests/fuzz/ has the open-ended libFuzzer target.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "common/input_error.hpp"
#include "scene/derive.hpp"
#include "scene/parse.hpp"
#include "support.hpp"

namespace pbflow {
namespace {

using nlohmann::json;

std::string scene_text(const std::string& name) {
  std::ifstream in(std::string(PBFLOW_TEST_DATA) + "/../scenes/" + name + ".json");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

const char* kValues[] = {"1e308", "-1e308", "1e400", "-1e400", "4.9e-324", "0", "-0", "-1", "1", "0.5",
                         "18446744073709551616", "-9223372036854775809", "2147483648", "true", "null", "\"x\"",
                         "[]", "{}", "[1,2]", "[1e308,1e308,1e308]", "[0,0,0]", "[-1e308,0,1e308]", "NaN", "Infinity"};

std::string nested(int depth, std::mt19937& random) {
  std::string open, close;
  for (int k = 0; k < depth; ++k) {
    const bool array = random() % 2;
    open += array ? "[" : "{\"a\":";
    close += array ? ']' : '}';
  }
  return open + "1" + std::string(close.rbegin(), close.rend());
}

// Every place in `j` a value sits, as JSON pointers.
void paths(const json& j, const json::json_pointer& at, std::vector<json::json_pointer>& out) {
  out.push_back(at);
  if (j.is_object())
    for (auto it = j.begin(); it != j.end(); ++it) paths(it.value(), at / it.key(), out);
  if (j.is_array())
    for (size_t k = 0; k < j.size(); ++k) paths(j[k], at / std::to_string(k), out);
}

// Reads `text` as a scene; true when it was accepted, false when refused with InputError.
// Any other exception fails the test; a crash or a sanitizer report ends it.
bool reads(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    Scene s = parse_scene(text, "mutant", overrides);
    derive(s);
    return true;
  } catch (const InputError&) {
    return false;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an InputError: " << e.what() << "\n  input: " << text.substr(0, 300);
    return false;
  }
}

TEST(SceneProperty, EveryMutationOfABuiltInSceneReadsOrIsRefused) {
  std::mt19937 random(2026);
  size_t accepted = 0, refused = 0;
  for (const auto& builtin : builtin_scenes()) {
    const json base = json::parse(scene_text(builtin.name));
    std::vector<json::json_pointer> where;
    paths(base, json::json_pointer(), where);
    for (int trial = 0; trial < 80; ++trial) {
      const json::json_pointer at = where[random() % where.size()];
      std::string text;
      if (trial % 10 == 9) {  // cut short anywhere
        text = base.dump();
        text.resize(random() % text.size());
      } else {
        json mutant = base;
        const std::string value = trial % 5 == 0 ? nested(1 + int(random() % 200000), random)
                                                 : std::string(kValues[random() % std::size(kValues)]);
        const std::string marker = "\"@@VALUE@@\"";
        if (at.empty()) {
          text = value;
        } else {
          mutant[at] = "@@VALUE@@";
          text = mutant.dump();
          text.replace(text.find(marker), marker.size(), value);
        }
      }
      (reads(text) ? accepted : refused)++;
    }
  }
  std::printf("[ property ] %zu mutants read, %zu refused\n", accepted, refused);
  EXPECT_GT(refused, 0u);
  EXPECT_GT(accepted, 0u);
}

TEST(SceneProperty, EveryParamValueReadsOrIsRefused) {
  std::mt19937 random(7);
  const std::string base = scene_text("dam_break");
  size_t refused = 0;
  for (const std::string key : {"particle_spacing", "frames", "fps", "solver.iterations", "solver.ldc_strength",
                                "solver.substeps", "camera.eye", "camera.fov", "gravity", "obstacles", "settle",
                                "description", "domain.min", "fluid_blocks"}) {
    for (const char* value : kValues) refused += !reads(base, {key + "=" + value});
    refused += !reads(base, {key + "=" + nested(100000, random)});
    refused += !reads(base, {key + "=not json {"});
  }
  EXPECT_GT(refused, 0u);
}

}  // namespace
}  // namespace pbflow
