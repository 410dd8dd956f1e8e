#pragma once
/// \file Progress.hpp
/// Progress of a running job: a human line on stderr and, with --progress-json, one JSON object per line
/// on stdout ({"fraction","sim_time","wall_time","eta_s"} and, once the job names it, "phase";
/// docs/contracts.md, "Progress") -- what the server's workers read. Throttled to about one report per
/// `interval` seconds of wall time. The ETA uses the rate of the last minute (EtaEstimate).

#include <chrono>
#include <deque>
#include <string>
#include <utility>

namespace rcfd {

/// Remaining wall time from the rate over the last `window` seconds of reports, not since the start:
/// a job whose machine got busy (or idle again) shows an estimate that follows within the window
/// instead of one averaged over the whole run (a demo starved by a build showed 7 h for 10 min left).
class EtaEstimate {
 public:
  /// Starts from nothing done at wall time 0.
  explicit EtaEstimate(double windowSeconds = 60.0) : window_(windowSeconds) { restart(0.0, 0.0); }
  /// Starts over from `fraction` done at wall time `t` [s].
  void restart(double t, double fraction) {
    samples_.clear();
    samples_.emplace_back(t, fraction);
  }
  /// Adds `fraction` done at wall time `t` [s] (non-decreasing); returns the seconds left, or -1 while
  /// no progress has been seen in the window.
  double update(double t, double fraction);

 private:
  double window_;
  std::deque<std::pair<double, double>> samples_;  ///< (wall time [s], fraction), oldest first
};

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
  void setStartFraction(double fraction) { eta_.restart(wallTime(), fraction); }
  /// Names the phase the job is in ("fill", "sample", "recurrence", ...): the "phase" of every later
  /// report. A new phase is reported at the next report() whatever the interval, so a reader sees it
  /// as soon as it starts.
  void setPhase(std::string phase);
  const std::string& phase() const { return phase_; }

 private:
  bool json_;
  double interval_;
  std::string label_;
  std::string phase_;
  bool phaseReported_ = true;
  double prior_ = 0.0;
  std::chrono::steady_clock::time_point start_;
  double lastReport_ = -1e300;
  EtaEstimate eta_;
};

}  // namespace rcfd
