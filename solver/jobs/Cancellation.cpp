#include "jobs/Cancellation.hpp"

#include <atomic>
#include <csignal>

namespace rcfd {
namespace {
std::atomic<bool> cancelFlag{false};
extern "C" void onSignal(int) { cancelFlag.store(true); }
}  // namespace

void installCancellationHandlers() {
  struct sigaction action {};
  action.sa_handler = onSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool cancellationRequested() { return cancelFlag.load(std::memory_order_relaxed); }
void requestCancellation(bool value) { cancelFlag.store(value); }

}  // namespace rcfd
