#include "analysis/StayComparison.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace rcfd::analysis {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// The smallest value whose cumulative weight reaches q of the total (the lower quantile, as the
/// histogram median of ZoneStays).
double quantile(const std::vector<std::pair<double, double>>& sorted, double total, double q) {
  double seen = 0.0;
  for (const auto& [value, weight] : sorted) {
    seen += weight;
    if (seen >= q * total * (1.0 - 1e-12)) return value;
  }
  return sorted.empty() ? 0.0 : sorted.back().first;
}

nlohmann::json numberOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

double relative(double value, double reference) { return reference != 0.0 ? (value - reference) / reference : kNaN; }

nlohmann::json toJson(const StaySummary& s) {
  return {{"stays", s.stays},
          {"mean_s", s.mean_s},
          {"median_s", s.median_s},
          {"p90_s", s.p90_s},
          {"crossings_per_member_per_s", numberOrNull(s.crossingRate > 0.0 ? s.crossingRate : kNaN)}};
}

}  // namespace

WeightedSample onStepLattice(const std::vector<double>& durations, double dt, double* unseen) {
  // Accumulated per k: the lattice distribution has one value per whole number of steps.
  std::vector<double> weight;
  double missed = 0.0;
  for (const double d : durations) {
    const double steps = d / dt;
    // A duration within rounding of a whole number of steps is that number (the reference's samples
    // often divide dt).
    double k = std::floor(steps + 1e-9);
    const double frac = std::max(0.0, steps - k);
    const std::size_t kk = std::size_t(k);
    if (weight.size() < kk + 2) weight.resize(kk + 2, 0.0);
    weight[kk] += 1.0 - frac;
    weight[kk + 1] += frac;
  }
  WeightedSample out;
  for (std::size_t k = 0; k < weight.size(); ++k) {
    if (k == 0) {
      missed = weight[0];
      continue;
    }
    if (weight[k] > 0.0) out.values.push_back(double(k) * dt), out.weights.push_back(weight[k]);
  }
  if (unseen) *unseen = durations.empty() ? 0.0 : missed / double(durations.size());
  return out;
}

WeightedSample fromStepCounts(const std::vector<std::int64_t>& counts, double dt) {
  WeightedSample out;
  for (std::size_t k = 1; k < counts.size(); ++k) {
    if (counts[k] > 0) out.values.push_back(double(k) * dt), out.weights.push_back(double(counts[k]));
  }
  return out;
}

WeightedSample windowCorrected(const WeightedSample& sample, double period, double longest, double* beyond) {
  if (beyond) *beyond = 0.0;
  if (!(period > 0.0)) return sample;
  WeightedSample out;
  double total = 0.0, left = 0.0;
  for (std::size_t i = 0; i < sample.values.size(); ++i) {
    const double d = sample.values[i], w = sample.weights.empty() ? 1.0 : sample.weights[i];
    total += w;
    if (d > longest) {
      left += w;
      continue;
    }
    out.values.push_back(d);
    out.weights.push_back(w * period / (period - d));
  }
  if (beyond && total > 0.0) *beyond = left / total;
  return out;
}

StaySummary summariseStays(const WeightedSample& sample, double members, double period) {
  StaySummary s;
  std::vector<std::pair<double, double>> sorted;
  double total = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < sample.values.size(); ++i) {
    const double w = sample.weights.empty() ? 1.0 : sample.weights[i];
    sorted.emplace_back(sample.values[i], w);
    total += w, sum += w * sample.values[i];
  }
  std::sort(sorted.begin(), sorted.end());
  s.stays = total;
  if (total > 0.0) {
    s.mean_s = sum / total;
    s.median_s = quantile(sorted, total, 0.5);
    s.p90_s = quantile(sorted, total, 0.9);
  }
  s.crossingRate = members > 0.0 && period > 0.0 ? total / (members * period) : 0.0;
  return s;
}

double StayComparison::meanError() const { return relative(tracers.mean_s, reference.mean_s); }
double StayComparison::crossingRateError() const {
  return tracers.crossingRate > 0.0 && reference.crossingRate > 0.0 ? relative(tracers.crossingRate, reference.crossingRate)
                                                                    : kNaN;
}

nlohmann::json StayComparison::toJson() const {
  return {{"resolution", "reference stays put on the tracers' step lattice (docs/calibration.md)"},
          {"lattice_dt_s", latticeDt},
          {"window", {{"correction", "each stay weighted by P / (P - d) for its side's observed period P (docs/calibration.md)"},
                      {"tracers_s", tracerWindow},
                      {"reference_s", referenceWindow},
                      {"longest_compared_s", numberOrNull(longestCompared)},
                      {"tracers_beyond_fraction", tracersBeyond},
                      {"reference_beyond_fraction", referenceBeyond}}},
          {"tracers", analysis::toJson(tracers)},
          {"reference", analysis::toJson(reference)},
          {"reference_unseen_fraction", referenceUnseen},
          {"ks_distance", ksDistance},
          {"mean_relative_error", numberOrNull(meanError())},
          {"crossing_rate_relative_error", numberOrNull(crossingRateError())}};
}

StayComparison compareStays(const std::vector<std::int64_t>& tracerStepCounts, double dt, double tracers,
                            double tracerPeriod, const std::vector<double>& referenceDurations,
                            double referenceMembers, double referencePeriod) {
  StayComparison c;
  c.latticeDt = dt;
  c.tracerWindow = std::max(0.0, tracerPeriod);
  c.referenceWindow = std::max(0.0, referencePeriod);
  // Both windows known: compare what both see with weights of at most 2. One unknown: no correction
  // (the two sides' censoring cannot be matched).
  const bool windows = c.tracerWindow > 0.0 && c.referenceWindow > 0.0;
  c.longestCompared = windows ? 0.5 * std::min(c.tracerWindow, c.referenceWindow) : std::numeric_limits<double>::infinity();
  const WeightedSample t = windowCorrected(fromStepCounts(tracerStepCounts, dt), windows ? c.tracerWindow : 0.0,
                                           c.longestCompared, &c.tracersBeyond);
  const WeightedSample r = windowCorrected(onStepLattice(referenceDurations, dt, &c.referenceUnseen),
                                           windows ? c.referenceWindow : 0.0, c.longestCompared, &c.referenceBeyond);
  c.tracers = summariseStays(t, tracers, tracerPeriod);
  c.reference = summariseStays(r, referenceMembers, referencePeriod);
  c.ksDistance = t.empty() || r.empty() ? 1.0 : ksDistance(t, r);
  return c;
}

}  // namespace rcfd::analysis
