#pragma once
/// \file SeriesSpectrum.hpp
/// Mean, standard deviation and dominant frequency of a uniformly sampled series (the database job's
/// bed pressure drop): the periodogram |DFT|^2 of the series with its least-squares straight line
/// removed (so a slow drift does not masquerade as the lowest frequency), and the frequency of its
/// largest value above zero. The resolution is 1 / (N dt); spouting beds fluctuate at 1-20 Hz.

#include <optional>
#include <vector>

namespace rcfd::analysis {

struct SeriesSpectrum {
  double mean = 0.0;  ///< arithmetic mean [unit]
  double std = 0.0;   ///< population standard deviation about the mean [unit]
  /// Frequency of the periodogram maximum [Hz]; empty when the detrended series is identically zero
  /// (no fluctuation, e.g. a DEM-only job's pressure drop of 0).
  std::optional<double> dominantFrequency;
  double resolution = 0.0;          ///< frequency spacing 1 / (N dt) [Hz]
  std::vector<double> frequencies;  ///< k / (N dt), k = 1 .. N/2 [Hz]
  std::vector<double> power;        ///< periodogram |X_k|^2 dt / N at those frequencies [unit^2 s]
};

/// The series x_n sampled every dt [s]. rcfd::InputError for fewer than 4 samples, dt <= 0 or a
/// non-finite value (naming the sample).
SeriesSpectrum seriesSpectrum(const std::vector<double>& x, double dt);

/// x minus its least-squares straight line a + b n.
std::vector<double> detrended(const std::vector<double>& x);

}  // namespace rcfd::analysis
