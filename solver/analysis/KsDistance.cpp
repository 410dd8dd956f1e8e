#include "analysis/KsDistance.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <utility>

namespace rcfd::analysis {
namespace {

/// (value, weight) pairs sorted by value; validates the input and returns the total weight.
std::vector<std::pair<double, double>> sorted(const WeightedSample& s, const char* name, double& total) {
  if (!s.weights.empty() && s.weights.size() != s.values.size()) {
    throw std::invalid_argument(std::string("KS distance: sample ") + name + " has " +
                                std::to_string(s.values.size()) + " values but " +
                                std::to_string(s.weights.size()) + " weights");
  }
  std::vector<std::pair<double, double>> out;
  out.reserve(s.values.size());
  total = 0.0;
  for (std::size_t i = 0; i < s.values.size(); ++i) {
    const double w = s.weights.empty() ? 1.0 : s.weights[i];
    if (!std::isfinite(s.values[i]) || !std::isfinite(w) || w < 0.0) {
      throw std::invalid_argument(std::string("KS distance: sample ") + name + " entry " + std::to_string(i) +
                                  " has value " + std::to_string(s.values[i]) + " and weight " +
                                  std::to_string(w) + "; values must be finite and weights finite and >= 0");
    }
    if (w > 0.0) out.emplace_back(s.values[i], w);
    total += w;
  }
  if (!(total > 0.0)) throw std::invalid_argument(std::string("KS distance: sample ") + name + " is empty");
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

double WeightedSample::totalWeight() const {
  if (weights.empty()) return double(values.size());
  return std::accumulate(weights.begin(), weights.end(), 0.0);
}

double ksDistance(const WeightedSample& a, const WeightedSample& b) {
  double ta = 0.0, tb = 0.0;
  const auto pa = sorted(a, "a", ta), pb = sorted(b, "b", tb);
  // Merge walk: at each distinct value take every entry of both samples at that value, then compare.
  // Cumulative weights are divided by the totals only when compared: with counts (whole numbers,
  // exact in double) equal distributions give bit-equal quotients, so D is exactly 0.
  double ca = 0.0, cb = 0.0, d = 0.0;
  std::size_t i = 0, j = 0;
  while (i < pa.size() || j < pb.size()) {
    const double x = std::min(i < pa.size() ? pa[i].first : INFINITY, j < pb.size() ? pb[j].first : INFINITY);
    while (i < pa.size() && pa[i].first == x) ca += pa[i++].second;
    while (j < pb.size() && pb[j].first == x) cb += pb[j++].second;
    d = std::max(d, std::abs(ca / ta - cb / tb));
  }
  return std::min(1.0, d);  // rounding of the normalised sums must not report 1 + 1e-16
}

double ksDistance(const std::vector<double>& a, const std::vector<double>& b) {
  return ksDistance(WeightedSample::unweighted(a), WeightedSample::unweighted(b));
}

}  // namespace rcfd::analysis
