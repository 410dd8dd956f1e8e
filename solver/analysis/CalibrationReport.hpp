#pragma once
/// \file CalibrationReport.hpp
/// Turns the finished D0 runs of a calibration (DIR/runs/d0_<i>/{result.h5,summary.json}) into the
/// job's scores, selection, result.h5 and figures. Pure post-processing: it reads only those files,
/// so an interrupted-and-resumed calibration reports exactly what an uninterrupted one does.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "analysis/CalibrationSelection.hpp"
#include "analysis/ReferenceStatistics.hpp"
#include "fields/FieldDatabase.hpp"
#include "scene/Scene.hpp"

namespace rcfd::analysis {

struct CalibrationInputs {
  const Scene& scene;
  const FieldDatabase& database;
  const std::vector<double>& d0;  ///< run i is DIR/runs/d0_<i>
  std::string runsDir;
  const ReferenceStatistics& reference;
  SelectionOptions options;
  std::int64_t steps = 0;         ///< per run
  std::int64_t discardSteps = 0;
};

/// Writes result.h5 (/calibration/..., layout in docs/calibration.md) and, when figureDir is not
/// empty, the SVG figures there. Returns the calibration part of summary.json: "d0", "selected_d0",
/// "penalty_minimum_d0", "selection_reason", "selection", "reference" (and "figures").
nlohmann::json writeCalibrationReport(const CalibrationInputs& inputs, const std::string& resultPath,
                                      const std::string& figureDir);

/// Index of the grid's cell layer holding the apparatus mid-plane z = depth / 2.
int midplaneLayer(const Scene& scene, const CartesianGrid& grid);

/// Probability density [1/s] of weighted durations over `edges` (values beyond the last edge go into
/// the last bin).
std::vector<double> densityHistogram(const std::vector<double>& values, const std::vector<double>& weights,
                                     const std::vector<double>& edges);

}  // namespace rcfd::analysis
