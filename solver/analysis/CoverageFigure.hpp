#pragma once
/// \file CoverageFigure.hpp
/// Several spray runs' coverage distributions (Eq. 15) in one figure, as the paper's Fig. 12 puts the
/// beds with and without draft plates side by side: one step line per run (the fraction of its tracers
/// in each bin), its median dashed, and a legend with mean, median, p10 and p90.

#include <string>
#include <vector>

#include "spray/Coverage.hpp"

namespace rcfd::analysis {

struct CoverageRun {
  std::string label;
  std::vector<double> coverage;  ///< phi per tracer [-]
};

/// /coverage/per_tracer of a spray job's result.h5. rcfd::InputError naming the file and the dataset
/// when it has none (a job without the `coverage` effect, or not a result file), or when it is empty.
std::vector<double> readTracerCoverage(const std::string& resultPath);

/// Draws the runs' distributions in `bins` bins (at least 1) over the range their values span, widened
/// to [0, 1] where they reach it, and returns each run's statistics (same bins) in the runs' order.
std::vector<Distribution> writeCoverageFigure(const std::vector<CoverageRun>& runs, int bins,
                                              const std::string& svgPath);

}  // namespace rcfd::analysis
