#include "jobs/Cancellation.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <thread>

#include "core/Errors.hpp"

namespace rcfd {
namespace {
std::atomic<bool> cancelFlag{false};
/// CLOCK_MONOTONIC of the request [ns]: clock_gettime is async-signal-safe, std::chrono is not
/// promised to be.
std::atomic<std::int64_t> requestedAtNs{0};

std::atomic<double> watchdogDeadline{0.0};
std::atomic<bool> watchdogStarted{false};
std::atomic<bool> forcedExitDecided{false};
std::atomic<int> deferrals{0};

std::int64_t monotonicNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void setFlag() {
  if (!cancelFlag.load()) requestedAtNs.store(monotonicNs());
  cancelFlag.store(true);
}

extern "C" void onSignal(int) { setFlag(); }

[[noreturn]] void forcedExit(double deadline) {
  forcedExitDecided.store(true);
  // A write that began before the decision is finished; one that begins after it waits for the exit.
  while (deferrals.load() > 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  char message[200];
  const int length = std::snprintf(message, sizeof message,
                                   "cancelled: no stopping point within %.3g s of the signal; exiting without "
                                   "a new checkpoint\n",
                                   deadline);
  (void)!::write(STDERR_FILENO, message, std::size_t(std::max(0, std::min(length, int(sizeof message) - 1))));
  ::_exit(exit_code::cancelled);
}

void watch() {
  for (;;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const double deadline = watchdogDeadline.load();
    if (cancelFlag.load() && secondsSinceCancellation() >= deadline) forcedExit(deadline);
  }
}
}  // namespace

void installCancellationHandlers() {
  struct sigaction action {};
  action.sa_handler = onSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool cancellationRequested() { return cancelFlag.load(std::memory_order_relaxed); }

void requestCancellation(bool value) {
  if (value) {
    setFlag();
  } else {
    cancelFlag.store(false);
  }
}

double secondsSinceCancellation() {
  if (!cancelFlag.load()) return 0.0;
  return double(monotonicNs() - requestedAtNs.load()) * 1e-9;
}

void startCancellationWatchdog(double deadlineSeconds) {
  watchdogDeadline.store(deadlineSeconds);
  if (watchdogStarted.exchange(true)) return;
  std::thread(watch).detach();
}

ForcedExitDeferral::ForcedExitDeferral() {
  deferrals.fetch_add(1);
  if (forcedExitDecided.load()) {
    // Too late to start a write the exit would cut: give the count back and wait for the exit.
    deferrals.fetch_sub(1);
    for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
  }
}

ForcedExitDeferral::~ForcedExitDeferral() { deferrals.fetch_sub(1); }

}  // namespace rcfd
