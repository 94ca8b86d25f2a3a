#pragma once
// JSON a user hands in (a scene file, a --param value, a run directory's run.json), parsed
// with a nesting limit: nlohmann's parser keeps its own stack, but serialising and reading
// a value recurse, and a scene nested 100 000 deep overflowed the stack (SIGSEGV).
#include <nlohmann/json.hpp>
#include <string>

#include "common/input_error.hpp"

namespace pbflow {

// Deeper than any scene or manifest pbflow reads (a scene's deepest key is three levels).
constexpr int kMaxJsonDepth = 64;

// Throws InputError naming `origin` for a syntax error, a number past double's range, or
// nesting deeper than kMaxJsonDepth.
template <class Input>
nlohmann::json parse_user_json(Input&& input, const std::string& origin) {
  auto limit = [&](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
    if (depth > kMaxJsonDepth)
      throw InputError(origin + ": JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    return true;
  };
  try {
    return nlohmann::json::parse(std::forward<Input>(input), limit);
  } catch (const nlohmann::json::exception& e) {  // parse_error; out_of_range for numbers past double's
    throw InputError(origin + ": JSON syntax error: " + e.what());
  }
}

}  // namespace pbflow
