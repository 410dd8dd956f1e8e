#include "jobs/Progress.hpp"

#include <cstdio>
#include <nlohmann/json.hpp>

namespace rcfd {

ProgressReporter::ProgressReporter(bool json, double intervalSeconds, std::string label)
    : json_(json), interval_(intervalSeconds), label_(std::move(label)), start_(std::chrono::steady_clock::now()) {}

double ProgressReporter::wallTime() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void ProgressReporter::report(double fraction, double simTime, bool force) {
  const double now = wallTime();
  if (!force && now - lastReport_ < interval_) return;
  lastReport_ = now;
  const double done = fraction - startFraction_;
  const double eta = done > 0.0 ? now / done * (1.0 - fraction) : -1.0;
  const double wall = prior_ + now;
  if (json_) {
    nlohmann::json line = {{"fraction", fraction}, {"sim_time", simTime}, {"wall_time", wall},
                           {"eta_s", eta >= 0.0 ? nlohmann::json(eta) : nlohmann::json(nullptr)}};
    std::printf("%s\n", line.dump().c_str());
    std::fflush(stdout);
  }
  if (eta >= 0.0) {
    std::fprintf(stderr, "%s%5.1f%%  t = %.3f s  wall %.1f s  eta %.0f s\n", label_.c_str(), 100.0 * fraction,
                 simTime, wall, eta);
  } else {
    std::fprintf(stderr, "%s%5.1f%%  t = %.3f s  wall %.1f s\n", label_.c_str(), 100.0 * fraction, simTime, wall);
  }
}

}  // namespace rcfd
