#include "analysis/CalibrationFigures.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/AxisTicks.hpp"
#include "core/Svg.hpp"

namespace rcfd::analysis {
namespace {

std::string colour(std::size_t i, std::size_t n) {
  return colormap(n > 1 ? 0.9 * double(i) / double(n - 1) : 0.0).hex();
}

double maxOf(const std::vector<std::vector<double>>& v, double floor) {
  double m = floor;
  for (const auto& s : v)
    for (const double x : s) m = std::max(m, x);
  return m;
}

std::string penaltyFigure(const CalibrationFigureData& d, const std::string& dir) {
  // Log x axis; D0 = 0 sits one decade below the smallest positive value, labelled "0".
  double minPositive = 1e-5;
  for (const double v : d.d0)
    if (v > 0.0) minPositive = std::min(minPositive, v);
  double maxPositive = minPositive;
  for (const double v : d.d0) maxPositive = std::max(maxPositive, v);
  auto xOf = [&](double v) { return v > 0.0 ? std::log10(v) : std::log10(minPositive) - 1.0; };
  // Whole decades, so the axis ticks fall on them: the labels read log10 D0.
  const double xa = std::floor(std::log10(minPositive)) - 2.0, xb = std::ceil(std::log10(maxPositive)) + 1.0;
  double ymax = 0.0;
  for (const double p : d.penalty) ymax = std::max(ymax, p);
  ymax = ymax > 0.0 ? 1.15 * ymax : 1.0;
  SvgDocument svg(xa, xb, 0.0, ymax, 560, 360, 55);
  svg.axes("log10 D0 [m2/s] (the left-most point is D0 = 0)", "penalty (1/N) ||alpha_P - alpha_P,rec||_2",
           int(xb - xa), 5);
  std::vector<std::size_t> order(d.d0.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return d.d0[a] < d.d0[b]; });
  std::vector<std::array<double, 2>> pts;
  for (const auto i : order) pts.push_back({xOf(d.d0[i]), d.penalty[i]});
  svg.polyline(pts, "#1f4e99", 1.5);
  for (const auto i : order) {
    const bool sel = i == d.selected, min = i == d.penaltyMinimum;
    svg.circle(xOf(d.d0[i]), d.penalty[i], sel ? 6 : 4, sel ? "#d62728" : (min ? "#2ca02c" : "#1f4e99"));
    svg.text(xOf(d.d0[i]), d.penalty[i] + 0.04 * ymax, d0Label(d.d0[i]), 9, "middle");
  }
  svg.textPx(60, 16, "Penalty vs D0 (Fig. 8); red: selected, green: penalty minimum", 13);
  const std::string name = "calibration_penalty.svg";
  svg.save(dir + "/" + name);
  return name;
}

std::string probeFigure(const CalibrationFigureData& d, const std::string& dir) {
  // One panel per D0, stacked: panel i spans y in [i * 1.25, i * 1.25 + 1] for alpha_P in [0, amax].
  const std::size_t n = d.d0.size();
  const double amax = std::max(0.7, maxOf(d.probeTracer, 0.0));
  double tmin = 1e300, tmax = -1e300;
  for (const auto& t : d.probeTime)
    if (!t.empty()) tmin = std::min(tmin, t.front()), tmax = std::max(tmax, t.back());
  if (!(tmax > tmin)) tmin = 0.0, tmax = 1.0;
  const double span = 1.25;
  SvgDocument svg(tmin, tmax, 0.0, span * double(n) - 0.25, 640, 110.0 * double(n) + 60, 55);
  // Time axis only: the y extent holds one panel per D0.
  svg.rect(tmin, 0.0, tmax, span * double(n) - 0.25, "none", "#000", 1.0);
  const std::vector<double> ticks = niceTicks(tmin, tmax, 5);
  for (const double t : ticks) {
    svg.line(t, 0.0, t, -0.05);
    svg.textPx(svg.px(t), svg.py(0.0) + 17, tickLabel(t, tickStep(ticks)), 10, "middle");
  }
  svg.textPx((svg.px(tmin) + svg.px(tmax)) / 2, 110.0 * double(n) + 55, "t [s]; probe " + d.probeName, 12, "middle");
  for (std::size_t r = 0; r < n; ++r) {
    const double base = span * double(n - 1 - r);
    svg.rect(tmin, base, tmax, base + 1.0, "none", "#999", 0.5);
    svg.line(tmin, base + 0.67 / amax, tmax, base + 0.67 / amax, "#999", 0.5, "2,3");  // close packing
    std::vector<std::array<double, 2>> rec, tr;
    for (std::size_t k = 0; k < d.probeTime[r].size(); ++k) {
      rec.push_back({d.probeTime[r][k], base + d.probeRecurrence[r][k] / amax});
      tr.push_back({d.probeTime[r][k], base + d.probeTracer[r][k] / amax});
    }
    svg.polyline(rec, "#000", 1.0);
    svg.polyline(tr, "#d62728", 1.0);
    svg.text(tmin, base + 1.02, "D0 = " + d0Label(d.d0[r]) + " m2/s (red: tracers, black: recurrence, dotted: 0.67)", 10);
  }
  svg.textPx(60, 16, "Probe alpha_P per D0 against the recurrence field (Fig. 7)", 13);
  const std::string name = "calibration_probe_series.svg";
  svg.save(dir + "/" + name);
  return name;
}

std::string holdupFigure(const CalibrationFigureData& d, const std::string& dir) {
  const std::size_t n = d.d0.size();
  std::size_t len = 0;
  for (const auto& h : d.holdup) len = std::max(len, h.size());
  const double tEnd = d.holdupT0 + double(std::max<std::size_t>(len, 1)) * d.holdupDt;
  double ymax = maxOf(d.holdup, 1.0);
  for (const double h : d.referenceHoldup) ymax = std::max(ymax, h);
  SvgDocument svg(d.holdupT0, tEnd, 0.0, 1.1 * ymax, 640, 380, 60);
  svg.axes("t [s]", "spray-zone holdup [particles]");
  std::vector<std::string> labels, colours;
  for (std::size_t r = 0; r < n; ++r) {
    std::vector<std::array<double, 2>> pts;
    double mean = 0.0;
    for (std::size_t k = 0; k < d.holdup[r].size(); ++k) {
      pts.push_back({d.holdupT0 + double(k) * d.holdupDt, d.holdup[r][k]});
      mean += d.holdup[r][k];
    }
    mean /= double(std::max<std::size_t>(1, d.holdup[r].size()));
    svg.polyline(pts, colour(r, n), 1.0);
    svg.line(d.holdupT0, mean, tEnd, mean, colour(r, n), 1.0, "2,3");
    svg.text(tEnd, mean, " " + d0Label(d.d0[r]), 9, "start", colour(r, n));
  }
  if (!d.referenceHoldup.empty()) {
    std::vector<std::array<double, 2>> pts;
    double mean = 0.0;
    for (std::size_t k = 0; k < d.referenceHoldup.size(); ++k) {
      const double t = d.holdupT0 + double(k) * d.referenceHoldupDt;
      if (t > tEnd) break;
      pts.push_back({t, d.referenceHoldup[k]});
    }
    for (const double h : d.referenceHoldup) mean += h;
    mean /= double(d.referenceHoldup.size());
    svg.polyline(pts, "#000", 1.5);
    svg.line(d.holdupT0, mean, tEnd, mean, "#000", 1.0, "2,3");
    svg.text(tEnd, mean, " CFD-DEM", 9, "start");
  }
  svg.textPx(60, 16, "Spray-zone holdup per D0 (Fig. 10); dotted: time averages" +
                         std::string(d.referenceHoldup.empty() ? "; no reference" : "; black: CFD-DEM"), 13);
  const std::string name = "calibration_holdup.svg";
  svg.save(dir + "/" + name);
  return name;
}

std::string rtdFigure(const CalibrationFigureData& d, const std::string& dir) {
  const std::size_t n = d.d0.size();
  const double tmax = d.rtdEdges.empty() ? 1.0 : d.rtdEdges.back();
  double ymax = maxOf(d.rtdDensity, 0.0);
  for (const double v : d.referenceRtdDensity) ymax = std::max(ymax, v);
  ymax = ymax > 0.0 ? 1.1 * ymax : 1.0;
  SvgDocument svg(0.0, tmax, 0.0, ymax, 640, 380, 60);
  svg.axes("residence time in the spray zone [s]", "probability density [1/s]");
  auto steps = [&](const std::vector<double>& density, const std::string& stroke, double width) {
    std::vector<std::array<double, 2>> pts;
    for (std::size_t b = 0; b < density.size(); ++b) {
      pts.push_back({d.rtdEdges[b], density[b]});
      pts.push_back({d.rtdEdges[b + 1], density[b]});
    }
    svg.polyline(pts, stroke, width);
  };
  for (std::size_t r = 0; r < n; ++r) {
    steps(d.rtdDensity[r], colour(r, n), 1.2);
    svg.text(tmax, ymax * (0.95 - 0.06 * double(r)), "D0 = " + d0Label(d.d0[r]) + " ", 10, "end", colour(r, n));
  }
  if (!d.referenceRtdDensity.empty()) steps(d.referenceRtdDensity, "#000", 2.0);
  svg.textPx(60, 16, "Spray-zone residence-time distributions (Fig. 11)" +
                         std::string(d.referenceRtdDensity.empty() ? "; no reference" : "; black: CFD-DEM on the tracers' step lattice"), 13);
  const std::string name = "calibration_rtd.svg";
  svg.save(dir + "/" + name);
  return name;
}

std::string midplaneFigure(const CalibrationFigureData& d, const std::string& dir) {
  // Panels side by side: every D0, then the recurrence average; colour scale alpha_P in [0, 0.65].
  const std::size_t panels = d.midplane.size() + 1;
  const double w = d.x1 - d.x0, gap = 0.15 * w, h = d.y1 - d.y0;
  const double scale = 0.65;
  const double panelPx = std::clamp(600.0 / double(panels), 90.0, 200.0);
  SvgDocument svg(0.0, double(panels) * (w + gap), d.y0, d.y1, panelPx * double(panels), panelPx * h / w * 1.0 + 40,
                  45);
  auto draw = [&](const std::vector<float>& values, std::size_t p, const std::string& title) {
    std::vector<double> v(values.size());
    for (std::size_t c = 0; c < v.size(); ++c) v[c] = std::clamp(double(values[c]) / scale, 0.0, 1.0);
    const double left = double(p) * (w + gap);
    svg.heatmap(v, d.nx, d.ny, left, left + w, d.y0, d.y1);
    svg.rect(left, d.y0, left + w, d.y1, "none", "#000", 0.5);
    svg.text(left + 0.5 * w, d.y1 + 0.02 * h, title, 10, "middle");
  };
  for (std::size_t r = 0; r < d.midplane.size(); ++r) draw(d.midplane[r], r, "D0 = " + d0Label(d.d0[r]));
  draw(d.recurrenceMidplane, panels - 1, "Recurrence");
  svg.textPx(10, 14, "Time-averaged alpha_P on the mid-plane (Fig. 9); colour 0 (dark) .. 0.65 (bright)", 12);
  const std::string name = "calibration_midplane.svg";
  svg.save(dir + "/" + name);
  return name;
}

}  // namespace

std::string d0Label(double d0) {
  if (d0 == 0.0) return "0";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0e", d0);
  return buf;
}

std::vector<std::string> writeCalibrationFigures(const CalibrationFigureData& data, const std::string& outDir) {
  return {penaltyFigure(data, outDir), probeFigure(data, outDir), holdupFigure(data, outDir), rtdFigure(data, outDir),
          midplaneFigure(data, outDir)};
}

}  // namespace rcfd::analysis
