#include "jobs/Progress.hpp"

#include <cstdio>
#include <nlohmann/json.hpp>

namespace rcfd {

ProgressReporter::ProgressReporter(bool json, double intervalSeconds, std::string label)
    : json_(json), interval_(intervalSeconds), label_(std::move(label)), start_(std::chrono::steady_clock::now()) {}

double EtaEstimate::update(double t, double fraction) {
  samples_.emplace_back(t, fraction);
  // Keep the newest sample at or before the window's start, so the rate spans the whole window.
  while (samples_.size() > 2 && samples_[1].first <= t - window_) samples_.pop_front();
  const auto& [t0, f0] = samples_.front();
  const double rate = t > t0 ? (fraction - f0) / (t - t0) : 0.0;
  return rate > 0.0 ? (1.0 - fraction) / rate : -1.0;
}

double ProgressReporter::wallTime() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void ProgressReporter::setPhase(std::string phase) {
  if (phase == phase_) return;
  phase_ = std::move(phase);
  phaseReported_ = false;
}

void ProgressReporter::report(double fraction, double simTime, bool force) {
  const double now = wallTime();
  if (!force && phaseReported_ && now - lastReport_ < interval_) return;
  lastReport_ = now;
  phaseReported_ = true;
  const double eta = eta_.update(now, fraction);
  const double wall = prior_ + now;
  if (json_) {
    nlohmann::json line = {{"fraction", fraction}, {"sim_time", simTime}, {"wall_time", wall},
                           {"eta_s", eta >= 0.0 ? nlohmann::json(eta) : nlohmann::json(nullptr)}};
    if (!phase_.empty()) line["phase"] = phase_;
    std::printf("%s\n", line.dump().c_str());
    std::fflush(stdout);
  }
  const std::string label = label_ + (phase_.empty() ? "" : phase_ + " ");
  if (eta >= 0.0) {
    std::fprintf(stderr, "%s%5.1f%%  t = %.3f s  wall %.1f s  eta %.0f s\n", label.c_str(), 100.0 * fraction,
                 simTime, wall, eta);
  } else {
    std::fprintf(stderr, "%s%5.1f%%  t = %.3f s  wall %.1f s\n", label.c_str(), 100.0 * fraction, simTime, wall);
  }
}

}  // namespace rcfd
