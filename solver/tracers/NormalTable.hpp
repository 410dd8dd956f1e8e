#pragma once
/// \file NormalTable.hpp
/// Standard normal numbers from a table of quantiles, three from one 64-bit draw: the quantiles of
/// the 4096 equiprobable bins' midpoints, Phi^-1((i + 1/2) / 4096), scaled to unit variance. A
/// discrete stand-in for the Gaussian whose mean is 0 and variance exactly 1, bounded at 3.7: for
/// velocity kicks summed over many steps its shape is the Gaussian's to far below any statistic
/// rcfd reports, at a few nanoseconds a number where Box-Muller's logarithm and sine cost tens.

#include <array>
#include <cmath>
#include <cstdint>

namespace rcfd {

class NormalTable {
 public:
  static constexpr int kBits = 12;
  static constexpr int kSize = 1 << kBits;

  static const NormalTable& instance() {
    static const NormalTable table;
    return table;
  }

  /// The three numbers of one draw (its lowest 36 bits).
  void three(std::uint64_t draw, double out[3]) const {
    for (int k = 0; k < 3; ++k) out[k] = double(values_[std::size_t((draw >> (kBits * k)) & (kSize - 1))]);
  }

  const std::array<float, kSize>& values() const { return values_; }

 private:
  NormalTable() {
    std::array<double, kSize> z{};
    double sumSquares = 0.0;
    for (int i = 0; i < kSize; ++i) {
      const double p = (double(i) + 0.5) / double(kSize);
      double lo = -10.0, hi = 10.0;  // Phi(z) = erfc(-z / sqrt 2) / 2 is increasing: bisection
      for (int it = 0; it < 80; ++it) {
        const double mid = 0.5 * (lo + hi);
        (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
      }
      z[std::size_t(i)] = 0.5 * (lo + hi);
      sumSquares += z[std::size_t(i)] * z[std::size_t(i)];
    }
    const double scale = 1.0 / std::sqrt(sumSquares / double(kSize));
    for (int i = 0; i < kSize; ++i) values_[std::size_t(i)] = float(z[std::size_t(i)] * scale);
  }
  std::array<float, kSize> values_{};
};

}  // namespace rcfd
