#include "app/serve.hpp"

#include <chrono>
#include <csignal>
#include <iostream>
#include <thread>

#include "app/interrupt.hpp"
#include "app/live_run.hpp"
#include "app/web_server.hpp"

namespace pbflow {

int serve(const ServeOptions& o) {
  InterruptGuard interrupt;
  if (!o.live.run.video.empty() || !o.live.run.export_format.empty() || !o.live.run.render)
    throw InputError("serve draws its frames for the browser: --video, --export and --no-render are for `pbflow run`");
  LiveRun run(o.live);
  WebServer server(o.listen, run);
  const std::string host = o.listen.substr(0, o.listen.rfind(':'));
  std::cerr << "pbflow: " << run.description() << ", drawn at " << o.live.run.width * run.panels() << "x"
            << o.live.run.height << "\n"
            << "pbflow: open http://" << host << ":" << server.port() << "/ (Ctrl-C stops)\n";
  if (!server.token().empty())
    std::cerr << "pbflow: listening on " << o.listen << ", which other machines can reach: they may watch, and steer "
              << "with the token " << server.token() << "\n";
  while (!interrupt.signal() && run.failure().empty()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  run.stop();
  if (const std::string why = run.failure(); !why.empty()) {
    std::cerr << "pbflow: the live run stopped: " << why << "\n";
    return 1;
  }
  std::cerr << "pbflow: stopped by " << (interrupt.signal() == SIGINT ? "SIGINT" : "SIGTERM") << "\n";
  return 0;
}

}  // namespace pbflow
