#pragma once
/// \file Progress.hpp
/// Progress of a running job: a human line on stderr and, with --progress-json, one JSON object per line
/// on stdout ({"fraction","sim_time","wall_time","eta_s"} and, once the job names them, "phase" and
/// "phase_fraction"; docs/contracts.md, "Progress") -- what the server's workers read. Throttled to
/// about one report per `interval` seconds of wall time. The ETA is EtaEstimator's: the rate of the
/// last minute, limited to a factor 2 per minute once 30 s have passed.
///
/// `fraction` is the whole job's, each runner weighting its phases by their expected cost so that it
/// grows about linearly in wall time (a rate measured in one phase then predicts the others);
/// `phase_fraction` is how far the current phase is, so a reader sees a long phase move even where
/// its weight in the whole is small.

#include <chrono>
#include <cstdint>
#include <string>

#include "jobs/EtaEstimator.hpp"

namespace rcfd {

/// How often this process has been continued after a stop (SIGCONT), counted from the first
/// ProgressReporter on: the reporter leaves a stopped stretch out of its ETA.
std::uint64_t processContinuations();

class ProgressReporter {
 public:
  ProgressReporter(bool json, double intervalSeconds = 1.0, std::string label = "");
  /// Reports if the interval has passed (or `force`); fraction in [0, 1], simTime [s].
  void report(double fraction, double simTime, bool force = false);
  /// Seconds since construction.
  double wallTime() const;
  /// Wall seconds already spent before a resume, counted into wall_time.
  void setPriorWallTime(double seconds) { prior_ = seconds; }
  /// Fraction already done when this process started (so the ETA uses this process's rate only).
  void setStartFraction(double fraction) {
    lastEtaUpdate_ = wallTime();
    eta_.restart(lastEtaUpdate_, fraction);
  }
  /// Names the phase the job is in ("fill", "sample", "recurrence", ...): the "phase" of every later
  /// report. A new phase is reported at the next report() whatever the interval, so a reader sees it
  /// as soon as it starts. Clears the phase fraction.
  void setPhase(std::string phase);
  const std::string& phase() const { return phase_; }
  /// How far the current phase is, in [0, 1]: the "phase_fraction" of the next reports (until the next
  /// setPhase()). Negative: not known.
  void setPhaseFraction(double fraction) { phaseFraction_ = fraction; }

 private:
  bool json_;
  double interval_;
  std::string label_;
  std::string phase_;
  double phaseFraction_ = -1.0;
  bool phaseReported_ = true;
  double prior_ = 0.0;
  std::chrono::steady_clock::time_point start_;
  double lastReport_ = -1e300;
  EtaEstimator eta_;
  double lastEtaUpdate_ = 0.0;           ///< wall time of the estimator's last update [s]
  std::uint64_t seenContinuations_ = 0;  ///< processContinuations() at that update
};

/// A duration as people read it: "45 s", "12 min 05 s", "3 h 07 min"; "?" when negative or not finite.
std::string humanDuration(double seconds);

}  // namespace rcfd
