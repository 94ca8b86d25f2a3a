#pragma once
// Scenes from JSON (docs/design.md, "Scene format"): built-in scenes, files, --param overrides,
// every key checked as the key table (scene/keys.hpp) says.
#include <string>
#include <vector>

#include "scene/scene.hpp"

namespace pbflow {

// SCENE is a built-in name or a JSON file; overrides are "dotted.key=value" (value
// read as JSON, else as a string). Throws InputError naming the problem.
Scene load_scene(const std::string& name_or_path, const std::vector<std::string>& overrides = {});
Scene parse_scene(const std::string& json_text, const std::string& origin,
                  const std::vector<std::string>& overrides = {});

struct BuiltinScene {
  std::string name, description;
};
std::vector<BuiltinScene> builtin_scenes();

}  // namespace pbflow
