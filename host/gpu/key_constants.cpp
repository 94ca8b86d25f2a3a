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
  std::vector<const SceneKey*> solver_keys;
  for (const SceneKey& k : scene_keys()) {
    const bool of_solver = std::holds_alternative<double SolverParams::*>(k.target) ||
                           std::holds_alternative<int SolverParams::*>(k.target) ||
                           std::holds_alternative<bool SolverParams::*>(k.target);
    if (of_solver) solver_keys.push_back(&k);
  }
  names_.reserve(solver_keys.size());  // the constants view these strings: no reallocation
  for (const SceneKey* k : solver_keys) {
    const std::string& name = names_.emplace_back(shader_name(k->name));
    if (auto m = std::get_if<double SolverParams::*>(&k->target)) constants_.emplace_back(name, float(p.**m));
    if (auto m = std::get_if<int SolverParams::*>(&k->target)) constants_.emplace_back(name, p.**m);
    if (auto m = std::get_if<bool SolverParams::*>(&k->target)) constants_.emplace_back(name, p.**m);
  }
}

}  // namespace pbflow
