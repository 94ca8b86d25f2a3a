#pragma once
// SIGINT, SIGTERM and SIGHUP during a run: caught and remembered, so that the run stops between
// frames with its files whole (run.cpp), instead of dying in the middle of a write.
namespace pbflow {

class InterruptGuard {
 public:
  InterruptGuard();   // installs the handlers
  ~InterruptGuard();  // restores the previous ones
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

  int signal() const;  // the signal received, 0 while none
};

const char* signal_name(int signal);  // "SIGINT", "SIGTERM", "SIGHUP"

}  // namespace pbflow
