#include "gpu/key_constants.hpp"

#include <cctype>
#include <type_traits>
#include <variant>

#include "gpu/buffer_plan.hpp"

namespace pbflow {

std::string KeyConstants::shader_name(std::string_view key) {
  std::string name;
  for (char c : key) name += c == '.' ? '_' : char(std::toupper(static_cast<unsigned char>(c)));
  return name;
}

KeyConstants::KeyConstants(const Derived& d) {
  // The obstacles' shapes, a bit each: those the scene lacks compile out (shaders/solids.glsl).
  uint32_t shapes = 0;
  for (const Obstacle& o : d.obstacles) shapes |= 1u << uint32_t(o.kind);
  constants_.emplace_back("SHAPES", shapes);
  constants_.emplace_back("OBSTACLE_COUNT", int(d.obstacles.size()));  // the loops over them unroll
  constants_.emplace_back("MOVING", d.moving());  // and whether any moves: their work is counted
  constants_.emplace_back("WALLS", d.walls_mirror);  // whether the box's walls mirror (not for a mesh tank)
  constants_.emplace_back("BODIES", !d.bodies.empty());  // whether any obstacle is a body: its pushes are summed
  constants_.emplace_back("OBSTACLE_MIRRORS", true);  // but not in the far list readers (GpuSolver::neighbour_pass)
  constants_.emplace_back("DISTANCES", keeps_distances(d));  // the particles' distances from the obstacles, kept
  constants_.emplace_back("STICKY", d.sticky());  // whether the fluid sticks to any obstacle
  for (const ParamKey& k : d.shader_keys) {
    auto offer = [&](auto value) { constants_.emplace_back(names_.emplace_back(shader_name(k.name)), value); };
    auto offer_member = [&](const auto& params) {
      using P = std::decay_t<decltype(params)>;
      if (auto m = std::get_if<double P::*>(&k.target)) offer(float(params.**m));
      if (auto m = std::get_if<int P::*>(&k.target)) offer(params.**m);
      if (auto m = std::get_if<bool P::*>(&k.target)) offer(params.**m);
    };
    offer_member(d.solver);
    offer_member(d.white_water);
  }
}

}  // namespace pbflow
