#include "analysis/CoverageFigure.hpp"

#include <algorithm>
#include <array>
#include <cstdio>

#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "core/Svg.hpp"

namespace rcfd::analysis {
namespace {

constexpr const char* kCoverageDataset = "/coverage/per_tracer";
/// Colours the eye tells apart, also in grey print (dark blue, orange, green, red, purple).
constexpr std::array<const char*, 5> kColours{"#3b518b", "#e08214", "#35b779", "#c00000", "#7b3294"};

}  // namespace

std::vector<double> readTracerCoverage(const std::string& resultPath) {
  h5::File f(resultPath, h5::File::Mode::ReadOnly);
  if (!f.exists(kCoverageDataset))
    throw InputError(resultPath, kCoverageDataset,
                     "no coverage per tracer: not the result.h5 of a spray job whose scene lists `coverage`");
  std::vector<double> phi = f.readDoubles(kCoverageDataset);
  if (phi.empty()) throw InputError(resultPath, kCoverageDataset, "no tracers");
  return phi;
}

std::vector<Distribution> writeCoverageFigure(const std::vector<CoverageRun>& runs, int bins,
                                              const std::string& svgPath) {
  if (runs.empty()) throw InputError("coverage figure", "", "no runs to draw");
  bins = std::max(bins, 1);
  // The range the values span: a spray of an hour crowds near 1, a short one near 0.
  double lo = 1.0, hi = 0.0;
  for (const auto& r : runs)
    for (double v : r.coverage) lo = std::min(lo, v), hi = std::max(hi, v);
  lo = std::max(0.0, lo);
  hi = std::min(1.0, hi);
  if (!(hi - lo > 1e-6)) lo = std::max(0.0, lo - 0.05), hi = std::min(1.0, hi + 0.05);
  std::vector<Distribution> d;
  double top = 0.0;
  for (const auto& r : runs) {
    d.push_back(describe(r.coverage, bins, lo, hi));
    for (auto c : d.back().counts) top = std::max(top, double(c) / double(r.coverage.size()));
  }
  top *= 1.1 + 0.08 * double(runs.size());  // room for the legend
  SvgDocument svg(lo, hi, 0.0, top, 680, 440, 60);
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const std::string colour = kColours[k % kColours.size()];
    const double n = double(runs[k].coverage.size());
    std::vector<std::array<double, 2>> steps;
    for (std::size_t b = 0; b < d[k].counts.size(); ++b) {
      const double y = double(d[k].counts[b]) / n;
      steps.push_back({d[k].edges[b], y});
      steps.push_back({d[k].edges[b + 1], y});
    }
    svg.polyline(steps, colour, 2.0);
    svg.line(d[k].median, 0.0, d[k].median, top, colour, 1.2, "5,3");
    char legend[200];
    std::snprintf(legend, sizeof legend, "%s: mean %.3f, median %.3f, p10 %.3f, p90 %.3f (%zu tracers)",
                  runs[k].label.c_str(), d[k].mean, d[k].median, d[k].p10, d[k].p90, runs[k].coverage.size());
    const double y = top * (0.95 - 0.07 * double(k));
    svg.line(lo + 0.02 * (hi - lo), y, lo + 0.07 * (hi - lo), y, colour, 2.0);
    svg.text(lo + 0.08 * (hi - lo), y, legend, 12, "start", colour);
  }
  svg.axes("surface coverage phi [-] (Eq. 15)", "fraction of tracers per bin [-]");
  svg.textPx(340, 20, "Coverage distributions (medians dashed)", 14, "middle");
  svg.save(svgPath);
  return d;
}

}  // namespace rcfd::analysis
