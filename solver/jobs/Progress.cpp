#include "jobs/Progress.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <mutex>
#include <nlohmann/json.hpp>

namespace rcfd {
namespace {

std::atomic<std::uint64_t> continuations{0};

void onContinue(int) { continuations.fetch_add(1, std::memory_order_relaxed); }

/// Counts SIGCONT from now on; SA_RESTART, so no system call of the job sees EINTR for it.
void countContinuations() {
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction action {};
    action.sa_handler = onContinue;
    action.sa_flags = SA_RESTART;
    sigemptyset(&action.sa_mask);
    sigaction(SIGCONT, &action, nullptr);
  });
}

}  // namespace

std::uint64_t processContinuations() { return continuations.load(std::memory_order_relaxed); }

ProgressReporter::ProgressReporter(bool json, double intervalSeconds, std::string label)
    : json_(json), interval_(intervalSeconds), label_(std::move(label)), start_(std::chrono::steady_clock::now()) {
  countContinuations();
  seenContinuations_ = processContinuations();
}

double ProgressReporter::wallTime() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void ProgressReporter::setPhase(std::string phase) {
  if (phase == phase_) return;
  phase_ = std::move(phase);
  phaseFraction_ = -1.0;
  phaseReported_ = false;
}

std::string humanDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0) return "?";
  const long s = std::lround(seconds);
  char out[48];
  if (s >= 3600) std::snprintf(out, sizeof out, "%ld h %02ld min", s / 3600, (s % 3600) / 60);
  else if (s >= 60) std::snprintf(out, sizeof out, "%ld min %02ld s", s / 60, s % 60);
  else std::snprintf(out, sizeof out, "%ld s", s);
  return out;
}

void ProgressReporter::report(double fraction, double simTime, bool force) {
  const double now = wallTime();
  if (!force && phaseReported_ && now - lastReport_ < interval_) return;
  lastReport_ = now;
  phaseReported_ = true;
  fraction = std::clamp(fraction, 0.0, 1.0);
  // A stop since the last update (SIGSTOP ... SIGCONT) is time the job did not run: left out of the
  // rate, so the estimate goes on from where it stood (the wall time still counts it).
  if (const std::uint64_t c = processContinuations(); c != seenContinuations_) {
    seenContinuations_ = c;
    eta_.skip(now - lastEtaUpdate_ - interval_);  // the reporting interval of it ran
  }
  const double eta = eta_.update(now, fraction);
  lastEtaUpdate_ = now;
  const double wall = prior_ + now;
  const bool phaseKnown = !phase_.empty() && phaseFraction_ >= 0.0;
  const double phaseFraction = std::min(1.0, phaseFraction_);
  if (json_) {
    nlohmann::json line = {{"fraction", fraction}, {"sim_time", simTime}, {"wall_time", wall},
                           {"eta_s", eta >= 0.0 ? nlohmann::json(eta) : nlohmann::json(nullptr)}};
    if (!phase_.empty()) line["phase"] = phase_;
    if (phaseKnown) line["phase_fraction"] = phaseFraction;
    std::printf("%s\n", line.dump().c_str());
    std::fflush(stdout);
  }
  std::string text = label_;
  char buffer[160];
  if (!phase_.empty()) {
    text += phase_;
    if (phaseKnown) {
      std::snprintf(buffer, sizeof buffer, " %3.0f%%", 100.0 * phaseFraction);
      text += buffer;
    }
    text += ", ";
  }
  std::snprintf(buffer, sizeof buffer, "%5.1f%% in all  t = %.3f s  wall %s", 100.0 * fraction, simTime,
                humanDuration(wall).c_str());
  text += buffer;
  if (eta >= 0.0) text += "  eta " + humanDuration(eta);
  std::fprintf(stderr, "%s\n", text.c_str());
}

}  // namespace rcfd
