#pragma once
/// \file Coverage.hpp
/// Surface coverage of a particle after collecting N droplets, Eq. (15) (Kariuki et al. 2013):
/// phi = 1 - (1 - f)^N with f = (d_D / (2 d_P))^2, and statistics of its distribution over particles.

#include <cmath>
#include <vector>

namespace rcfd {

/// Fraction of the particle surface one droplet covers, f = (d_D / (2 d_P))^2.
inline double singleDropletCoverage(double dropletDiameter, double particleDiameter) {
  const double r = dropletDiameter / (2.0 * particleDiameter);
  return r * r;
}

/// Eq. (15) for a real-valued N >= 0 (expected droplets per particle); log1p keeps it exact for tiny f.
inline double coverage(double droplets, double f) {
  if (!(droplets > 0.0)) return 0.0;
  return -std::expm1(droplets * std::log1p(-f));  // Eq. (15)
}

struct Distribution {
  double mean = 0.0, median = 0.0, p10 = 0.0, p90 = 0.0;
  std::vector<double> edges;      ///< bins + 1 edges on [lo, hi]
  std::vector<long long> counts;  ///< values per bin (the last bin includes hi)
};

/// Mean, quantiles (sorted copy, nearest rank) and a histogram of `values` on [lo, hi].
Distribution describe(std::vector<double> values, int bins, double lo, double hi);

}  // namespace rcfd
