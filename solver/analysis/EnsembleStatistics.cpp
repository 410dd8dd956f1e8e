#include "analysis/EnsembleStatistics.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rcfd::analysis {
namespace {

/// Continued fraction of the regularised incomplete beta function (modified Lentz).
double betaFraction(double a, double b, double x) {
  constexpr double tiny = 1e-300;
  double c = 1.0, d = 1.0 - (a + b) * x / (a + 1.0);
  if (std::abs(d) < tiny) d = tiny;
  d = 1.0 / d;
  double h = d;
  for (int m = 1; m <= 1000; ++m) {
    const double m2 = 2.0 * m;
    double aa = m * (b - m) * x / ((a + m2 - 1.0) * (a + m2));
    d = 1.0 + aa * d;
    d = std::abs(d) < tiny ? 1.0 / tiny : 1.0 / d;
    c = 1.0 + aa / c;
    if (std::abs(c) < tiny) c = tiny;
    h *= d * c;
    aa = -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0));
    d = 1.0 + aa * d;
    d = std::abs(d) < tiny ? 1.0 / tiny : 1.0 / d;
    c = 1.0 + aa / c;
    if (std::abs(c) < tiny) c = tiny;
    const double step = d * c;
    h *= step;
    if (std::abs(step - 1.0) < 1e-16) break;
  }
  return h;
}

/// I_x(a, b), the regularised incomplete beta function, for x in [0, 1].
double incompleteBeta(double a, double b, double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  const double front =
      std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x));
  if (x < (a + 1.0) / (a + b + 2.0)) return front * betaFraction(a, b, x) / a;
  return 1.0 - front * betaFraction(b, a, 1.0 - x) / b;
}

/// P(T <= t) for t >= 0 and `dof` degrees of freedom.
double studentTCdf(double t, double dof) {
  return 1.0 - 0.5 * incompleteBeta(0.5 * dof, 0.5, dof / (dof + t * t));
}

}  // namespace

double studentTQuantile(double p, int dof) {
  if (!(p > 0.0 && p < 1.0) || dof < 1) throw std::invalid_argument("studentTQuantile: p in (0, 1), dof >= 1");
  if (p < 0.5) return -studentTQuantile(1.0 - p, dof);
  if (p == 0.5) return 0.0;
  // Bisection on the monotone CDF: 200 halvings of [0, hi] reach double precision.
  double lo = 0.0, hi = 1.0;
  while (studentTCdf(hi, dof) < p) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (studentTCdf(mid, dof) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

Spread spreadOf(const std::vector<double>& values, double level) {
  Spread s;
  s.members = int(values.size());
  if (values.empty()) return s;
  double sum = 0.0;
  for (const double v : values) sum += v;
  s.mean = sum / double(values.size());
  s.min = *std::min_element(values.begin(), values.end());
  s.max = *std::max_element(values.begin(), values.end());
  if (s.min == s.max) s.mean = s.min;  // equal members: exactly their value, no spread from round-off
  s.ciLow = s.ciHigh = s.mean;
  if (values.size() < 2 || s.min == s.max) return s;
  double squares = 0.0;
  for (const double v : values) squares += (v - s.mean) * (v - s.mean);
  s.sd = std::sqrt(squares / double(values.size() - 1));
  s.sem = s.sd / std::sqrt(double(values.size()));
  const double t = studentTQuantile(1.0 - 0.5 * (1.0 - level), int(values.size()) - 1);
  s.ciLow = s.mean - t * s.sem;
  s.ciHigh = s.mean + t * s.sem;
  return s;
}

nlohmann::json toJson(const Spread& s, const std::vector<double>& values) {
  return {{"mean", s.mean}, {"sd", s.sd},   {"sem", s.sem},      {"ci95", {s.ciLow, s.ciHigh}},
          {"min", s.min},   {"max", s.max}, {"values", values}};
}

}  // namespace rcfd::analysis
