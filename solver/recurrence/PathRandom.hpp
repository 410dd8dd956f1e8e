#pragma once
/// \file PathRandom.hpp
/// Platform-independent draws for recurrence paths. std::mt19937_64's output sequence is fixed by the
/// C++ standard, but std::uniform_int_distribution and friends are implementation-defined, so the
/// integer and real mappings are written out here: the same seed gives the same path everywhere.

#include <cstdint>
#include <random>

namespace rcfd::path_random {

/// Uniform integer in [lo, hi] (lo <= hi) by rejection: no modulo bias.
inline std::int64_t uniformInt(std::mt19937_64& rng, std::int64_t lo, std::int64_t hi) {
  const std::uint64_t range = std::uint64_t(hi - lo) + 1u;
  if (range == 0) return std::int64_t(rng());  // the full 64-bit range
  const std::uint64_t threshold = (0u - range) % range;  // 2^64 mod range
  std::uint64_t x = rng();
  while (x < threshold) x = rng();  // [threshold, 2^64) holds a whole number of ranges
  return lo + std::int64_t(x % range);
}

/// Uniform double in [0, 1) from the top 53 bits.
inline double uniform01(std::mt19937_64& rng) { return double(rng() >> 11) * 0x1.0p-53; }

/// Threshold t with P(rng() < t) = q for q in [0, 1] (saturates at 1).
inline std::uint64_t bernoulliThreshold(double q) {
  if (!(q > 0.0)) return 0;
  const double scaled = q * 0x1.0p64;
  if (scaled >= 0x1.0p64) return ~std::uint64_t(0);
  return std::uint64_t(scaled);
}

}  // namespace rcfd::path_random
