#pragma once
/// \file UnitVectors.hpp
/// Uniform random unit vectors from a counter-based stream in a form the compiler vectorises: 32-bit
/// integer hashes, float arithmetic, and sin and cos of the azimuth from polynomials (Cephes' minimax
/// coefficients on [-pi/4, pi/4], error ~1 ulp) instead of libm's sincos, which does not vectorise.
/// The motion kernel draws the Eq. (10) direction of a whole block of tracers at once with it.

#include <cmath>
#include <cstdint>

#include "tracers/CounterRng.hpp"

namespace rcfd {

/// sin(2 pi u) and cos(2 pi u) for u in [0, 1) in float: a reduction to quarter turns (exact) and
/// Cephes' sinf/cosf minimax polynomials on [-pi/4, pi/4] (error ~1 ulp of float, about 6e-8).
inline void sinCosTwoPiFloat(float u, float& s, float& c) {
  const float w = 4.0f * u;
  const int j = int(w + 0.5f);
  const float r = (w - float(j)) * 1.57079632679489661923f;
  const float z = r * r;
  const float sr = r + r * z * ((-1.9515295891e-4f * z + 8.3321608736e-3f) * z - 1.6666654611e-1f);
  const float cr = 1.0f - 0.5f * z + z * z * ((2.443315711809948e-5f * z - 1.388731625493765e-3f) * z +
                                               4.166664568298827e-2f);
  const int q = j & 3;
  const float sa = (q & 1) ? cr : sr;
  const float ca = (q & 1) ? sr : cr;
  s = (q & 2) ? -sa : sa;
  c = ((q + 1) & 2) ? -ca : ca;
}

/// Chris Wellons' `lowbias32` (hash-prospector): a bijective 32-bit integer hash with full avalanche
/// (bias 0.17). 32-bit multiplications vectorise natively with AVX2; SplitMix64's 64-bit ones do not
/// (AVX2 has no 64-bit multiply: three 32-bit ones and shifts each).
constexpr std::uint32_t hash32(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

/// The two 24-bit integers a tracer's Eq. (10) direction is made of in step `prefix`: `zBits` for z
/// and `azimuthBits` for the azimuth. Two rounds of hash32(): the first keyed by the stream (a
/// bijection of the stream for one step, so no two tracers of a step share it), the second by the
/// first. The step's key is the lower and upper half of prefix.head ^ prefix.tail (SplitMix64 of the
/// seed, purpose and step). Streams are tracer identities, below 2^31.
inline void counterDirectionBits(const CounterRngPrefix& prefix, std::uint64_t stream, std::uint32_t& zBits,
                                 std::uint32_t& azimuthBits) {
  const std::uint64_t key = prefix.head ^ prefix.tail;
  const std::uint32_t first = hash32(std::uint32_t(stream) ^ std::uint32_t(key));
  const std::uint32_t second = hash32(first + std::uint32_t(key >> 32));
  zBits = first >> 8;
  azimuthBits = second >> 8;
}

/// The random unit vector of stream `stream` (uniform on the sphere) in float arithmetic, from
/// counterDirectionBits(): z = 2 u1 - 1 and the azimuth 2 pi u2 with u = bits / 2^24. The motion
/// kernel's Eq. (10) direction: its speed is a float per cell already, so a direction to float
/// precision (|n| = 1 within 3e-7) loses nothing, and float halves the vector work of the double form.
inline void counterUnitVectorFloat(const CounterRngPrefix& prefix, std::uint64_t stream, float& x, float& y, float& z) {
  std::uint32_t zBits, azimuthBits;
  counterDirectionBits(prefix, stream, zBits, azimuthBits);
  // 24-bit integers convert to float exactly, and 2 u1 - 1 is exact too.
  const float u1 = float(std::int32_t(zBits)) * 0x1.0p-24f;
  const float u2 = float(std::int32_t(azimuthBits)) * 0x1.0p-24f;
  const float zf = 2.0f * u1 - 1.0f;
  const float r2 = 1.0f - zf * zf;
  const float r = std::sqrt(r2 > 0.0f ? r2 : 0.0f);
  float s, c;
  sinCosTwoPiFloat(u2, s, c);
  x = r * c, y = r * s, z = zf;
}

/// counterUnitVectorFloat() as doubles.
inline void counterUnitVector(const CounterRngPrefix& prefix, std::uint64_t stream, double& x, double& y, double& z) {
  float fx, fy, fz;
  counterUnitVectorFloat(prefix, stream, fx, fy, fz);
  x = double(fx), y = double(fy), z = double(fz);
}

}  // namespace rcfd
