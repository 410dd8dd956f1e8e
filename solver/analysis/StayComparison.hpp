#pragma once
/// \file StayComparison.hpp
/// Spray-zone stays of the tracers against the full simulation's, at a common time resolution.
///
/// A tracer's stay is observed on the lattice of its steps: it counts the step ends at which the tracer
/// is inside, so it is a whole number k of steps dt, and a pass between two step ends is not seen at
/// all. The full simulation records stays on its own, finer lattice (1 / probe_rate). Comparing the two
/// as they are compares two measurements, not two motions. The reference is therefore put on the
/// tracers' lattice: a stay of duration d observed at step ends of a random phase covers
/// k = floor(d / dt) step ends with probability 1 - frac(d / dt) and k + 1 with probability frac(d / dt)
/// (the phase of a stay's entry is uniform against the steps). Each reference stay becomes these two
/// weighted lattice durations; the weight at k = 0 is the share of stays the lattice does not see. Both
/// sides then count, average and rank the same observable. Exact in distribution for any d; the
/// reference's own sampling (within one of its samples of the true duration) stays in it.
///
/// Both sides also see their stays through a window of finite length: a stay counts only when it begins
/// and ends within the observed period P, which for a stationary flow happens to a share (P - d) / P of
/// the stays of duration d. Long stays are under-counted, the more so the shorter the window, so a 2 s
/// reference against 8 s of tracers would compare two censorings, not two motions. Each counted stay is
/// weighted by P / (P - d) for its own side's P (Horvitz-Thompson), which estimates the stays that begin
/// within the period whatever their end; stays longer than half the shorter window (weights above 2,
/// and seen by that side only rarely) are left out on both sides and their share reported.

#include <nlohmann/json.hpp>
#include <vector>

#include "analysis/KsDistance.hpp"

namespace rcfd::analysis {

/// The reference durations [s] on the lattice of dt: values k dt (k >= 1) with their weights; the weight
/// of k = 0 (stays no step end sees) goes to *unseen when given.
WeightedSample onStepLattice(const std::vector<double>& durations, double dt, double* unseen = nullptr);

/// Tracer stays from their histogram over whole steps (counts[k] stays of k steps).
WeightedSample fromStepCounts(const std::vector<std::int64_t>& counts, double dt);

/// What a comparison reports of one side.
struct StaySummary {
  double stays = 0.0;         ///< (weighted) number of stays compared
  double mean_s = 0.0;        ///< [s]
  double median_s = 0.0;      ///< [s]
  double p90_s = 0.0;         ///< [s]
  double crossingRate = 0.0;  ///< stays per member per second [1/s] (0 when members or period unknown)
};
/// Mean, median, p90 of a weighted sample and its crossing rate over `members` observed for `period` s.
StaySummary summariseStays(const WeightedSample& sample, double members, double period);

/// The stays of a sample counted through a window of `period` s, corrected for the window: each stay of
/// duration d <= longest weighted by period / (period - d); stays above `longest` (which must be below
/// `period`) left out, their share of the weight going to *beyond when given. Unchanged when period <= 0
/// (unknown).
WeightedSample windowCorrected(const WeightedSample& sample, double period, double longest, double* beyond = nullptr);

/// Tracers against the reference on the tracers' lattice.
struct StayComparison {
  double latticeDt = 0.0;
  double tracerWindow = 0.0, referenceWindow = 0.0;  ///< observed periods [s] (0: unknown, no window correction)
  double longestCompared = 0.0;                      ///< [s]; infinite without window correction
  double tracersBeyond = 0.0, referenceBeyond = 0.0;  ///< share of each side's stays longer than that
  StaySummary tracers, reference;
  double ksDistance = 0.0;         ///< between the two lattice distributions
  double referenceUnseen = 0.0;    ///< share of reference stays the lattice does not see
  /// Relative differences (tracers - reference) / reference; NaN where the reference value is 0.
  double meanError() const;
  double crossingRateError() const;
  nlohmann::json toJson() const;
};

StayComparison compareStays(const std::vector<std::int64_t>& tracerStepCounts, double dt, double tracers,
                            double tracerPeriod, const std::vector<double>& referenceDurations,
                            double referenceMembers, double referencePeriod);

}  // namespace rcfd::analysis
