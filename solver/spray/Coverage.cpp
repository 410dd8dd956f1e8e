#include "spray/Coverage.hpp"

#include <algorithm>

namespace rcfd {

Distribution describe(std::vector<double> values, int bins, double lo, double hi) {
  Distribution d;
  bins = std::max(1, bins);
  d.edges.resize(std::size_t(bins) + 1);
  for (int b = 0; b <= bins; ++b) d.edges[std::size_t(b)] = lo + (hi - lo) * b / bins;
  d.counts.assign(std::size_t(bins), 0);
  if (values.empty()) return d;
  double sum = 0.0;
  for (double v : values) {
    sum += v;
    int b = int((v - lo) / (hi - lo) * bins);
    b = std::clamp(b, 0, bins - 1);
    ++d.counts[std::size_t(b)];
  }
  d.mean = sum / double(values.size());
  std::sort(values.begin(), values.end());
  auto quantile = [&](double q) {
    const std::size_t i = std::min(values.size() - 1, std::size_t(q * double(values.size() - 1) + 0.5));
    return values[i];
  };
  d.median = quantile(0.5);
  d.p10 = quantile(0.1);
  d.p90 = quantile(0.9);
  return d;
}

}  // namespace rcfd
