#pragma once
/// \file CalibrationFigures.hpp
/// The calibration job's SVG figures, after the paper's Figs. 7-11: penalty vs D0 (log axis), probe
/// alpha_P series per D0 against the recurrence value, spray-zone holdup series, residence-time
/// distributions per D0 against the reference, and mid-plane time-averaged alpha_P maps.

#include <string>
#include <vector>

namespace rcfd::analysis {

struct CalibrationFigureData {
  std::vector<double> d0;       ///< [m2/s], one entry per run
  std::vector<double> penalty;  ///< mean probe penalty per run
  std::size_t selected = 0, penaltyMinimum = 0;

  std::string probeName;  ///< the probe of the series figure
  std::vector<std::vector<double>> probeTime, probeTracer, probeRecurrence;  ///< per run

  std::vector<std::vector<double>> holdup;  ///< per run [particles], sampled every holdupDt from holdupT0
  double holdupDt = 0.0, holdupT0 = 0.0;
  std::vector<double> referenceHoldup;      ///< empty: no reference
  double referenceHoldupDt = 0.0;

  std::vector<double> rtdEdges;                  ///< common bin edges [s]
  std::vector<std::vector<double>> rtdDensity;   ///< per run, probability density [1/s]
  std::vector<double> referenceRtdDensity;       ///< empty: no reference

  int nx = 0, ny = 0;                  ///< mid-plane cells
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;  ///< mid-plane extent [m]
  std::vector<std::vector<float>> midplane;  ///< per run, time-averaged tracer alpha_P [ny][nx]
  std::vector<float> recurrenceMidplane;     ///< time-averaged recurrence alpha_P [ny][nx]
};

/// Writes calibration_{penalty,probe_series,holdup,rtd,midplane}.svg into outDir; returns the names.
std::vector<std::string> writeCalibrationFigures(const CalibrationFigureData& data, const std::string& outDir);

/// "0" or "1e-04"-style label of a D0 value.
std::string d0Label(double d0);

}  // namespace rcfd::analysis
