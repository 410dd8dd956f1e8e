#pragma once
/// \file EnsembleStatistics.hpp
/// Mean and spread of one statistic over the K members of an ensemble (independent realisations of a
/// run): the sample standard deviation of the members, the standard error of their mean and its
/// confidence interval from Student's t distribution with K - 1 degrees of freedom.

#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

namespace rcfd::analysis {

/// Quantile of Student's t distribution with `dof` >= 1 degrees of freedom: the t with
/// P(T <= t) = p, for p in (0, 1) (e.g. p = 0.975, dof = 3: 3.1824).
double studentTQuantile(double p, int dof);

struct Spread {
  int members = 0;
  double mean = 0.0;
  double sd = 0.0;   ///< sample standard deviation over the members (K - 1 in the denominator)
  double sem = 0.0;  ///< standard error of the mean, sd / sqrt(K)
  double ciLow = 0.0, ciHigh = 0.0;  ///< mean -+ t(1 - (1 - level) / 2, K - 1) sem
  double min = 0.0, max = 0.0;
};

/// The spread of `values` (one per member, in member order; summed in that order, so the result
/// does not depend on which thread ran which member). One value: sd, sem 0 and the interval the value.
Spread spreadOf(const std::vector<double>& values, double level = 0.95);

/// {"mean", "sd", "sem", "ci95": [low, high], "min", "max", "values": [...]}.
nlohmann::json toJson(const Spread& spread, const std::vector<double>& values);

}  // namespace rcfd::analysis
