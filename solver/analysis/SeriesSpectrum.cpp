#include "analysis/SeriesSpectrum.hpp"

#include <cmath>
#include <complex>
#include <string>
#include <unsupported/Eigen/FFT>

#include "core/Errors.hpp"

namespace rcfd::analysis {

std::vector<double> detrended(const std::vector<double>& x) {
  const double n = double(x.size());
  // Least squares of a + b t over t = 0 .. n-1, with t centred for conditioning.
  const double tMean = 0.5 * (n - 1.0);
  double xMean = 0.0;
  for (const double v : x) xMean += v;
  xMean /= n;
  double stt = 0.0, stx = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double t = double(i) - tMean;
    stt += t * t;
    stx += t * (x[i] - xMean);
  }
  const double slope = stt > 0.0 ? stx / stt : 0.0;
  std::vector<double> out(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) out[i] = x[i] - xMean - slope * (double(i) - tMean);
  return out;
}

SeriesSpectrum seriesSpectrum(const std::vector<double>& x, double dt) {
  constexpr std::size_t kMinimumSamples = 4;
  if (x.size() < kMinimumSamples) {
    throw InputError("series", "", std::to_string(x.size()) + " samples; a spectrum needs at least 4");
  }
  if (!(dt > 0.0) || !std::isfinite(dt)) throw InputError("series", "dt", std::to_string(dt) + " s; must be > 0");
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i])) throw InputError("series", "sample " + std::to_string(i), "is not finite");
  }
  SeriesSpectrum s;
  const std::size_t n = x.size();
  for (const double v : x) s.mean += v;
  s.mean /= double(n);
  for (const double v : x) s.std += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(s.std / double(n));
  s.resolution = 1.0 / (double(n) * dt);

  const std::vector<double> y = detrended(x);
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> spectrum;
  fft.fwd(spectrum, y);
  double best = 0.0;
  for (std::size_t k = 1; k <= n / 2; ++k) {
    const double p = std::norm(spectrum[k]) * dt / double(n);
    s.frequencies.push_back(double(k) * s.resolution);
    s.power.push_back(p);
    if (p > best) {  // the first of equal maxima: deterministic
      best = p;
      s.dominantFrequency = double(k) * s.resolution;
    }
  }
  // A series that is a straight line leaves only round-off: no dominant frequency.
  double scale = 0.0;
  for (const double v : x) scale = std::max(scale, std::abs(v));
  const double roundOff = 1e-24 * scale * scale * double(n) * dt;
  if (best <= roundOff) s.dominantFrequency.reset();
  return s;
}

}  // namespace rcfd::analysis
