#pragma once
/// \file KsDistance.hpp
/// Two-sample Kolmogorov-Smirnov distance, D = sup_x |F_a(x) - F_b(x)|, between empirical distributions
/// given as samples with weights (a histogram of exact values is a weighted sample). Used by the
/// calibration job to compare residence-time distributions of rCFD runs with the full simulation.

#include <vector>

namespace rcfd::analysis {

/// Values with non-negative weights (counts). An empty sample, or one of zero total weight, has no
/// distribution.
struct WeightedSample {
  std::vector<double> values;
  std::vector<double> weights;  ///< same length as values; empty means weight 1 each

  static WeightedSample unweighted(std::vector<double> values) { return {std::move(values), {}}; }
  double totalWeight() const;
  bool empty() const { return !(totalWeight() > 0.0); }
};

/// The two-sample KS distance in [0, 1]: 0 for identical distributions, 1 when every value of one
/// sample lies below every value of the other. Ties are handled exactly (both CDFs step at a shared
/// value before they are compared). Throws std::invalid_argument for an empty sample, a negative or
/// non-finite weight, a non-finite value or mismatched lengths.
double ksDistance(const WeightedSample& a, const WeightedSample& b);

/// Convenience for plain samples.
double ksDistance(const std::vector<double>& a, const std::vector<double>& b);

}  // namespace rcfd::analysis
