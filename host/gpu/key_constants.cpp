#include "gpu/key_constants.hpp"

#include <cctype>
#include <variant>

#include "scene/keys.hpp"

namespace pbflow {

std::string KeyConstants::shader_name(std::string_view key) {
  std::string name;
  for (char c : key) name += c == '.' ? '_' : char(std::toupper(static_cast<unsigned char>(c)));
  return name;
}

KeyConstants::KeyConstants(const SolverParams& p) {
  for (const SceneKey& k : scene_keys()) {
    auto offer = [&](auto value) { constants_.emplace_back(names_.emplace_back(shader_name(k.name)), value); };
    if (auto m = std::get_if<double SolverParams::*>(&k.target)) offer(float(p.**m));
    if (auto m = std::get_if<int SolverParams::*>(&k.target)) offer(p.**m);
    if (auto m = std::get_if<bool SolverParams::*>(&k.target)) offer(p.**m);
  }
}

}  // namespace pbflow
