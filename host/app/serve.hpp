#pragma once
// `pbflow serve`: a scene run live and watched in a browser (docs/serve.md).
#include <string>

#include "app/live_run.hpp"

namespace pbflow {

struct ServeOptions {
  LiveOptions live;  // the scene and image options as `pbflow run` takes them, --compare, --frame-budget
  std::string listen = "127.0.0.1:8080";
};

// Serves until SIGINT, SIGTERM or SIGHUP; returns the exit status. Throws InputError for bad input.
int serve(const ServeOptions& o);

}  // namespace pbflow
