#include "app/serve.hpp"

#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <iostream>
#include <mutex>
#include <thread>

#include "app/interrupt.hpp"
#include "app/live_run.hpp"
#include "app/web_server.hpp"

namespace pbflow {

namespace {

// A signal ends `serve` within 2 s whatever it is doing. The orderly stop (the run's thread
// between frames, every connection closed) is given 1.5 s; a step of the set-up or of a scene's
// load cannot be cut short on the device, and serve writes no file that an exit could cut, so
// past that the process ends at once.
class StopDeadline {
 public:
  explicit StopDeadline(const InterruptGuard& interrupt) : thread_([this, &interrupt] { watch(interrupt); }) {}
  ~StopDeadline() {
    {
      std::lock_guard lock(mutex_);
      done_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  StopDeadline(const StopDeadline&) = delete;
  StopDeadline& operator=(const StopDeadline&) = delete;

 private:
  void watch(const InterruptGuard& interrupt) {
    std::unique_lock lock(mutex_);
    while (!done_ && !interrupt.signal()) changed_.wait_for(lock, std::chrono::milliseconds(20));
    if (changed_.wait_for(lock, std::chrono::milliseconds(1500), [&] { return done_; })) return;
    std::cerr << "pbflow: stopped by " << signal_name(interrupt.signal()) << " (its work in hand dropped)\n";
    std::_Exit(0);
  }

  std::mutex mutex_;
  std::condition_variable changed_;
  bool done_ = false;
  std::thread thread_;  // last: it reads the rest
};

}  // namespace

int serve(const ServeOptions& o) {
  InterruptGuard interrupt;
  StopDeadline deadline(interrupt);
  if (!o.live.run.video.empty() || !o.live.run.export_format.empty() || !o.live.run.render)
    throw InputError("serve draws its frames for the browser: --video, --export and --no-render are for `pbflow run`");
  Listener listener(o.listen);  // before the set-up: a bad address or a port in use is said at once
  LiveRun run(o.live);
  WebServer server(std::move(listener), run);
  std::cerr << "pbflow: " << run.description() << ", drawn at " << o.live.run.width * run.panels() << "x"
            << o.live.run.height << "\n"
            << "pbflow: open http://" << o.listen.substr(0, o.listen.rfind(':')) << ":" << server.port()
            << "/ (Ctrl-C stops)\n";
  if (!server.token().empty())
    std::cerr << "pbflow: listening on " << o.listen << ", which other machines can reach: anyone may watch; "
              << "steering needs the token " << server.token() << ": open http://ADDRESS:" << server.port()
              << "/#token=" << server.token() << "\n";
  while (!interrupt.signal() && run.failure().empty()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  run.stop();
  if (const std::string why = run.failure(); !why.empty()) {
    std::cerr << "pbflow: the live run stopped: " << why << "\n";
    return 1;
  }
  std::cerr << "pbflow: stopped by " << signal_name(interrupt.signal()) << "\n";
  return 0;
}

}  // namespace pbflow
