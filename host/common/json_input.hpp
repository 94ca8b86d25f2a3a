#pragma once
// JSON a user hands in (a scene file, a --param value, a run directory's run.json), parsed
// with a nesting limit: nlohmann's parser keeps its own stack, but serialising and reading
// a value recurse, and a scene nested 100 000 deep overflowed the stack (SIGSEGV).
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "common/input_error.hpp"

namespace pbflow {

// Deeper than any scene or manifest pbflow reads (a scene's deepest key is three levels).
constexpr int kMaxJsonDepth = 64;

// Whether `text` opens more than `limit` arrays or objects at once, in one pass that skips
// strings. (nlohmann's parse callback can tell the depth too, but made parsing superlinear.)
inline bool json_nested_deeper_than(std::string_view text, int limit) {
  int depth = 0;
  bool in_string = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > limit) return true;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return false;
}

// Throws InputError naming `origin` for a syntax error, a number past double's range, or
// nesting deeper than kMaxJsonDepth.
inline nlohmann::json parse_user_json(std::string_view text, const std::string& origin) {
  if (json_nested_deeper_than(text, kMaxJsonDepth))
    throw InputError(origin + ": JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {  // parse_error; out_of_range for numbers past double's
    throw InputError(origin + ": JSON syntax error: " + e.what());
  }
}

}  // namespace pbflow
