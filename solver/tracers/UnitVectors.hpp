#pragma once
/// \file UnitVectors.hpp
/// Uniform random unit vectors from a counter-based stream in a form the compiler vectorises: the draws
/// of CounterRng(prefix, stream).unitVector() bit for bit, except that sin and cos of the azimuth come
/// from the polynomials below (Cephes' minimax coefficients on [-pi/4, pi/4], error ~1 ulp) instead of
/// libm's sincos, which does not vectorise. The motion kernel draws the Eq. (10) direction of a whole
/// block of tracers at once with it.

#include <cmath>
#include <cstdint>

#include "tracers/CounterRng.hpp"

namespace rcfd {

/// sin(2 pi u) and cos(2 pi u) for u in [0, 1).
inline void sinCosTwoPi(double u, double& s, double& c) {
  // Quarter turns: w = 4u exactly (power of 2), j the nearest quarter, r in [-pi/4, pi/4].
  const double w = 4.0 * u;
  const int j = int(w + 0.5);
  const double r = (w - double(j)) * (0.5 * 3.141592653589793238462643383279502884);
  const double z = r * r;
  const double sr =
      r + r * z *
              (((((1.58962301576546568060e-10 * z - 2.50507477628578072866e-8) * z + 2.75573136213857245213e-6) * z -
                 1.98412698295895385996e-4) * z + 8.33333333332211858878e-3) * z - 1.66666666666666307295e-1);
  const double cr =
      1.0 - 0.5 * z +
      z * z *
          (((((-1.13585365213876817300e-11 * z + 2.08757008419747316778e-9) * z - 2.75573141792967388112e-7) * z +
             2.48015872888517045348e-5) * z - 1.38888888888730564116e-3) * z + 4.16666666666665929218e-2);
  // sin(r + j pi/2), cos(r + j pi/2) by the quadrant j mod 4.
  const int q = j & 3;
  const double sa = (q & 1) ? cr : sr;
  const double ca = (q & 1) ? sr : cr;
  s = (q & 2) ? -sa : sa;
  c = ((q + 1) & 2) ? -ca : ca;
}

/// The unit vector CounterRng(prefix, stream).unitVector() draws (z and the azimuth from one 64-bit
/// draw), with sinCosTwoPi for the azimuth.
inline void counterUnitVector(const CounterRngPrefix& prefix, std::uint64_t stream, double& x, double& y, double& z) {
  const std::uint64_t key = mix64(prefix.head + stream) ^ prefix.tail;
  // nextU64() of draw 1, split into its upper and lower 32 bits; they convert exactly through int64.
  const std::uint64_t draw = mix64(key + 0x9e3779b97f4a7c15ULL);
  const double u1 = double(std::int64_t(draw >> 32)) * 0x1.0p-32;
  const double u2 = double(std::int64_t(draw & 0xffffffffULL)) * 0x1.0p-32;
  z = 2.0 * u1 - 1.0;
  const double r2 = 1.0 - z * z;
  const double r = std::sqrt(r2 > 0.0 ? r2 : 0.0);
  double s, c;
  sinCosTwoPi(u2, s, c);
  x = r * c, y = r * s;
}

}  // namespace rcfd
