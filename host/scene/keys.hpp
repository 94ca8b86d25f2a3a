#pragma once
// Every scene key, declared once: its dotted name, kind, default, accepted range, unit and
// a line on what it means. The parser's schema, its range checks and their messages, the
// defaults and `pbflow keys` (the README's key table, checked by tests/scene_keys_test.cpp)
// all read this table. Why each default is what it is: docs/physics.md.
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>

#include "scene/scene.hpp"

namespace pbflow {

enum class KeyKind {
  Number,   // a JSON number within `range`
  Whole,    // a whole number within `range`
  Boolean,  // true or false
  Method,   // "pbf" or "ldc"
  Text,     // a string
  Vector,   // three numbers, m or m/s^2, within 1e6 of the origin
  Box,      // {min, max}
  Boxes,    // a list of {min, max}
  Balls,    // a list of {centre, radius}
  Shapes,   // a list of {"type": "box" | "sphere", ...}
  Motion,   // {"type": "oscillate" | "rotate" | "keyframes", ...}
  Mesh,     // {"file", "scale", "position", "rotation"}
  Emitters, // a list of {centre, normal, radius | size, speed, start, stop}
};

struct KeyRange {
  double lo, hi;
  bool lo_open = false, hi_open = false;
  bool contains(double v) const { return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi); }
};

// Where a scalar key lands in the Scene; structured keys (vectors, boxes, lists) are read
// by the parser's own functions and land where it puts them.
// A group's keys (solver.*, white_water.*) land in its parameters (ParamTarget, the list of
// groups, sim/params.hpp).
using KeyTarget = std::variant<std::monostate, double Scene::*, int Scene::*, bool Scene::*, ParamTarget, double Camera::*>;

struct SceneKey {
  std::string_view name;       // dotted: "solver.iterations"
  KeyKind kind;
  std::string_view shown;      // a default that is not `value`: "required", "chosen"; empty: `value`'s
  std::optional<double> value;  // the default a scalar key starts from; none: required or derived
  std::optional<KeyRange> range;
  std::string_view unit;
  std::string_view meaning;    // one line
  std::string_view why_range;  // appended to the range error: why values past it are refused
  KeyTarget target;
};

std::span<const SceneKey> scene_keys();

// The default as a user reads it: "1", "true", "required", "chosen".
std::string shown_default(const SceneKey& k);

// The range as a message shows it: "[0, 0.3]", "(1, 4]".
std::string describe_range(const KeyRange& r);

// Puts a scalar key's value where its row says (a whole number or boolean as such); nothing
// for a key without a target.
void assign(const SceneKey& k, double value, Scene& s);

// A Scene holding every default of the table (the structured keys empty).
Scene scene_defaults();

// The table as Markdown, one row per key: what `pbflow keys` prints and the README holds.
std::string scene_keys_markdown();

}  // namespace pbflow
