#pragma once
/// \file CounterRng.hpp
/// Counter-based random numbers: a stateless hash of (seed, stream, step, draw). Each tracer draws from
/// its own stream keyed by its id and the step, so results do not depend on the number of threads, on
/// the order tracers are processed in, or on whether the run was resumed from a checkpoint.

#include <cmath>
#include <cstdint>
#include <numbers>

#include <Eigen/Core>

namespace rcfd {

/// SplitMix64's finaliser: a bijective 64-bit mix with full avalanche.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// Purposes of random draws, so different uses of the same (seed, id, step) never share numbers.
enum class RngPurpose : std::uint64_t {
  Initialisation = 1,
  Fluctuation = 2,
  SprayInjection = 3,
  Path = 4,
  Test = 5,
  Deposition = 6,
  Streams = 7,
  Langevin = 8,
};

/// The part of a CounterRng key shared by every stream of one (seed, purpose, step), hoisted out of
/// loops over tracers: CounterRng(prefix, stream) draws exactly the numbers of
/// CounterRng(seed, purpose, stream, step).
struct CounterRngPrefix {
  CounterRngPrefix(std::uint64_t seed, RngPurpose purpose, std::uint64_t step)
      : head(mix64(mix64(seed ^ 0x5851f42d4c957f2dULL) + std::uint64_t(purpose))),
        tail(mix64(step + 0x632be59bd9b4e019ULL)) {}
  std::uint64_t head, tail;
};

class CounterRng {
 public:
  CounterRng(std::uint64_t seed, RngPurpose purpose, std::uint64_t stream, std::uint64_t step)
      : CounterRng(CounterRngPrefix(seed, purpose, step), stream) {}
  CounterRng(const CounterRngPrefix& prefix, std::uint64_t stream)
      : key_(mix64(prefix.head + stream) ^ prefix.tail) {}

  std::uint64_t nextU64() { return mix64(key_ + 0x9e3779b97f4a7c15ULL * (++counter_)); }
  /// Uniform in [0, 1) with 53 random bits.
  double uniform() { return double(nextU64() >> 11) * 0x1.0p-53; }
  /// Uniform random unit vector (uniform on the sphere): z and the azimuth from the upper and lower
  /// 32 bits of one draw (a resolution of 2^-32 in both, far below anything a direction is used for).
  Eigen::Vector3d unitVector() {
    const std::uint64_t draw = nextU64();
    const double z = 2.0 * (double(std::uint32_t(draw >> 32)) * 0x1.0p-32) - 1.0;
    const double phi = 2.0 * std::numbers::pi * (double(std::uint32_t(draw)) * 0x1.0p-32);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
  }

 private:
  std::uint64_t key_;
  std::uint64_t counter_ = 0;
};

}  // namespace rcfd
