#pragma once
// Bad input (a scene file, an override, an option): the CLI exits with status 2 and prints
// the message, which names the key, option or file.
#include <stdexcept>

namespace pbflow {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace pbflow
