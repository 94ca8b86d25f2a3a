#pragma once
// The solver's and white water's keys as specialisation constants, offered to every particle
// pass: a shader reads the key solver.xsph by declaring `layout(constant_id = 100) const float SOLVER_XSPH = 0.0;` (a
// number key is a float, a whole one an int, a boolean a bool; Program refuses another type; ids
// from 100 on, clear of a pass's own), and the host sets it from the scene. A key's row in the
// table (scene/keys.cpp), which derive() lists in Derived::shader_keys, is thus its one
// declaration on both sides; docs/design.md, "Adding a parameter", walks through one. Also
// offered: OBSTACLES (constant_id 90), whether the scene has any.
#include <deque>
#include <span>
#include <string>
#include <vector>

#include "sim/params.hpp"
#include "vk/program.hpp"

namespace pbflow {

class KeyConstants {
 public:
  explicit KeyConstants(const Derived& d);
  KeyConstants(const KeyConstants&) = delete;  // the constants view names_
  KeyConstants& operator=(const KeyConstants&) = delete;
  KeyConstants(KeyConstants&&) = default;  // a deque's strings stay where they are
  KeyConstants& operator=(KeyConstants&&) = default;

  std::span<const vk::Constant> constants() const { return constants_; }
  // The constant's name for a key: solver.ldc_clamp -> SOLVER_LDC_CLAMP.
  static std::string shader_name(std::string_view key);

 private:
  std::deque<std::string> names_;  // grows without moving the strings the constants view
  std::vector<vk::Constant> constants_;
};

}  // namespace pbflow
