#pragma once
/// \file SingleSphereDrag.hpp
/// Drag on a single sphere for free-flying tracers (Schiller-Naumann, Newton beyond Re = 1000), in a
/// form the compiler vectorises, so the block path and the scalar path of the motion kernel compute
/// the same numbers. std::pow does not vectorise (GCC 12, glibc's libmvec only under -ffast-math).

#include <bit>
#include <cmath>
#include <cstdint>

namespace rcfd {

/// x^p for x >= 0 and moderate p (0 for x = 0) as exp(p log x) with polynomial log and exp: within
/// 2e-14 relative of std::pow for x in [1e-13, 1e3] at p = 0.687 (test). Selects pick constants, not
/// products: a conditional product blocks GCC's if-conversion under -ftrapping-math.
inline double powPositive(double x, double p) {
  // log x = e ln 2 + log m with m in [sqrt(1/2), sqrt(2)), e and m from the bits.
  const std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
  std::int64_t e = std::int64_t(bits >> 52) - 1023;
  double m = std::bit_cast<double>((bits & 0x000fffffffffffffULL) | 0x3ff0000000000000ULL);  // [1, 2)
  const bool high = m > 1.4142135623730951;
  m *= high ? 0.5 : 1.0;
  e += std::int64_t(high);
  // log m = 2 atanh(s) = 2 (s + s^3/3 + s^5/5 + ...), |s| <= 0.172: 12 terms reach 1e-18.
  const double s = (m - 1.0) / (m + 1.0), s2 = s * s;
  double series = 1.0 / 23.0;
  for (int k = 21; k >= 1; k -= 2) series = series * s2 + 1.0 / k;
  const double y = p * (double(e) * 0.6931471805599453094 + 2.0 * s * series);
  // exp y = 2^k exp r with r = y - k ln 2 in [-ln 2 / 2, ln 2 / 2] (ln 2 in two parts, Cody-Waite).
  const double k = std::rint(y * 1.4426950408889634074);
  const double r = (y - k * 0.693147180369123816490) - k * 1.90821492927058770002e-10;
  double taylor = 1.0 / 6227020800.0;  // 1/13!
  double factorial = 6227020800.0;
  for (int n = 13; n >= 1; --n) {
    factorial /= n;
    taylor = taylor * r + 1.0 / factorial;  // 1 / (n-1)!
  }
  const double scale = std::bit_cast<double>(std::uint64_t(std::int64_t(k) + 1023) << 52);
  return taylor * scale * (x > 0.0 ? 1.0 : 0.0);
}

/// Schiller-Naumann correction of Stokes drag, 1 + 0.15 Re^0.687, with the Newton regime constant
/// (C_D = 0.44) beyond Re = 1000: the factor f in tau = tau_Stokes / f.
inline double singleSphereDragFactor(double re) {
  const double schillerNaumann = 1.0 + 0.15 * powPositive(re, 0.687);
  const double newton = 0.44 * re / 24.0;
  return re < 1000.0 ? schillerNaumann : newton;
}

}  // namespace rcfd
