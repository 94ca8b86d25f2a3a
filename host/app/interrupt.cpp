#include "app/interrupt.hpp"

#include <csignal>

namespace pbflow {

namespace {

volatile std::sig_atomic_t received = 0;
struct sigaction previous_int, previous_term;

void remember(int signal) { received = signal; }

}  // namespace

InterruptGuard::InterruptGuard() {
  received = 0;
  struct sigaction action = {};
  action.sa_handler = remember;
  action.sa_flags = SA_RESTART;  // a write in flight completes; the run stops after the frame
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, &previous_int);
  sigaction(SIGTERM, &action, &previous_term);
}

InterruptGuard::~InterruptGuard() {
  sigaction(SIGINT, &previous_int, nullptr);
  sigaction(SIGTERM, &previous_term, nullptr);
}

int InterruptGuard::signal() const { return received; }

}  // namespace pbflow
