#pragma once
/// \file Progress.hpp
/// Progress of a running job: a human line on stderr and, with --progress-json, one JSON object per line
/// on stdout ({"fraction","sim_time","wall_time","eta_s"}, CONTRACTS.md) -- what the server's workers
/// read. Throttled to about one report per `interval` seconds of wall time.

#include <chrono>
#include <string>

namespace rcfd {

class ProgressReporter {
 public:
  ProgressReporter(bool json, double intervalSeconds = 1.0, std::string label = "");
  /// Reports if the interval has passed (or `force`); fraction in [0, 1], simTime [s].
  void report(double fraction, double simTime, bool force = false);
  /// Seconds since construction.
  double wallTime() const;
  /// Wall seconds already spent before a resume, counted into wall_time and the rate.
  void setPriorWallTime(double seconds) { prior_ = seconds; }
  /// Fraction already done when this process started (so the ETA uses this process's rate only).
  void setStartFraction(double fraction) { startFraction_ = fraction; }

 private:
  bool json_;
  double interval_;
  std::string label_;
  double prior_ = 0.0;
  double startFraction_ = 0.0;
  std::chrono::steady_clock::time_point start_;
  double lastReport_ = -1e300;
};

}  // namespace rcfd
