#pragma once
/// \file EtaEstimator.hpp
/// The remaining wall time of a job from its progress fraction: the `eta_s` of the progress lines
/// (jobs/Progress.hpp, docs/contracts.md "Progress").
///
/// Two stages:
///  - **Rate.** The fraction gained per wall second over the last `window` seconds (not since the
///    start: a machine that got busy or idle shows within the window). A stall longer than the window
///    stretches it back to the last progress, so the rate falls gradually instead of becoming unknown.
///    The raw estimate is (1 - fraction) / rate.
///  - **Limit.** Even a windowed rate swings when the cost of a percent changes (a phase that the
///    job's weights price too cheap or too dear, a stall in a long step), and a user who reads
///    "10 h" and a minute later "2 h" trusts neither. So once the estimator has run `settle` seconds
///    since its start or restart, the estimate it reports follows the raw one only within a factor
///    2 per `window`: between two updates dt apart it stays within
///        [(E - dt) / 2^(dt/window), max(E, floor) * 2^(dt/window)],  E the previous estimate,
///    downwards from the previous estimate counted down (a job on time counts down freely), upwards
///    from the previous estimate itself (counted down, an estimate below 86 s would shrink by more
///    than a factor 2 per minute lets it grow, and stick). Over any stretch s the estimate therefore
///    moves at most a factor 2^(s/window) besides the countdown: E(t + s) <= 2^(s/window) max(E(t),
///    floor) and E(t + s) >= E(t) / 2^(s/window) - s. Before any progress since the restart the raw
///    estimate is taken as infinite and the estimate rises as fast as allowed. When the rate holds,
///    the raw estimate is the true remaining time and the reported one reaches it geometrically and
///    then equals it.
///
/// `floor` lets an estimate that counted down to a few seconds rise to twice the floor at once: a
/// job that overran its estimate shows a sensible figure within a minute or two, not after doubling
/// from one second. A fraction that goes down (a job that found more work, a calibration sweep that
/// grows) is new information, not noise: the estimator restarts there.

#include <deque>
#include <utility>

namespace rcfd {

class EtaEstimator {
 public:
  struct Settings {
    double window = 60.0;   ///< [s] rate window; the estimate moves at most a factor 2 per window
    double settle = 30.0;   ///< [s] after a (re)start the raw estimate is reported unlimited this long
    double minSpan = 5.0;   ///< [s] of progress history needed before any estimate (-1 before)
    double floor = 10.0;    ///< [s] an estimate may always rise to 2^(dt/window) times this
  };

  EtaEstimator() : EtaEstimator(Settings{}) {}
  /// Starts from nothing done at wall time 0.
  explicit EtaEstimator(Settings settings) : s_(settings) { restart(0.0, 0.0); }

  /// Starts over from `fraction` done at wall time `t` [s]: a new process resuming from a checkpoint,
  /// whose earlier rate says nothing about this one.
  void restart(double t, double fraction);

  /// Adds `fraction` done at wall time `t` [s] (non-decreasing); returns the seconds left, or -1 while
  /// there is no estimate (less than minSpan seconds since the restart, or no progress yet). 0 once the
  /// fraction reaches 1.
  double update(double t, double fraction);

  /// Forgets `seconds` of wall time before the next update, as if they had not passed: the process was
  /// stopped (SIGSTOP, a suspended Slurm job) and neither ran nor could report. Without this, the first
  /// update after a long stop reads the stop as a stall and the estimate needs minutes to come back.
  void skip(double seconds);

  /// The unlimited estimate of the last update (-1: none).
  double raw() const { return raw_; }

 private:
  Settings s_;
  std::deque<std::pair<double, double>> samples_;  ///< (wall time [s], fraction), oldest first
  double start_ = 0.0;     ///< wall time of the last restart [s]
  double last_ = -1.0;     ///< last reported estimate [s], -1: none
  double lastTime_ = 0.0;  ///< when it was reported [s]
  double raw_ = -1.0;
};

}  // namespace rcfd
