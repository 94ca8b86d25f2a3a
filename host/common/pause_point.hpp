#pragma once
// Named moments at which a test can catch the process: with PBFLOW_TEST_PAUSE=NAME in its
// environment the process stops itself (SIGSTOP) at the point NAME, so that a test sends a
// signal at exactly that moment and then continues it (SIGCONT). Without it, nothing happens.
#include <csignal>
#include <cstdlib>
#include <cstring>

namespace pbflow {

inline void pause_point(const char* name) {
  static const char* wanted = std::getenv("PBFLOW_TEST_PAUSE");
  if (wanted && std::strcmp(wanted, name) == 0) std::raise(SIGSTOP);
}

}  // namespace pbflow
