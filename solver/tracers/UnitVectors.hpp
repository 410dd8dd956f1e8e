#pragma once
/// \file UnitVectors.hpp
/// Uniform random unit vectors from a counter-based stream in a form the compiler vectorises: float
/// arithmetic, and sin and cos of the azimuth from polynomials (Cephes' minimax coefficients on
/// [-pi/4, pi/4], error ~1 ulp) instead of libm's sincos, which does not vectorise. The motion kernel
/// draws the Eq. (10) direction of a whole block of tracers at once with it.

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

/// The random unit vector of stream `stream` (uniform on the sphere) in float arithmetic: z and the
/// azimuth from the upper and lower 24 bits of the draw CounterRng(prefix, stream).nextU64() gives
/// first (CounterRng::unitVector() takes 32 bits of each, in double). The Eq. (10) direction of the
/// motion kernel: its speed is a float per cell already, so a direction to float precision (|n| = 1
/// within 3e-7) loses nothing, and float halves the vector work of the double form.
inline void counterUnitVector(const CounterRngPrefix& prefix, std::uint64_t stream, double& x, double& y, double& z) {
  const std::uint64_t key = mix64(prefix.head + stream) ^ prefix.tail;
  const std::uint64_t draw = mix64(key + 0x9e3779b97f4a7c15ULL);  // nextU64() of draw 1
  // 24-bit integers convert to float exactly, and 2 u1 - 1 is exact too.
  const float u1 = float(std::int32_t(draw >> 40)) * 0x1.0p-24f;
  const float u2 = float(std::int32_t((draw >> 8) & 0xffffffULL)) * 0x1.0p-24f;
  const float zf = 2.0f * u1 - 1.0f;
  const float r2 = 1.0f - zf * zf;
  const float r = std::sqrt(r2 > 0.0f ? r2 : 0.0f);
  float s, c;
  sinCosTwoPiFloat(u2, s, c);
  x = double(r * c), y = double(r * s), z = double(zf);
}

}  // namespace rcfd
