#include "analysis/DatabaseFigures.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "analysis/CalibrationReport.hpp"
#include "core/AxisTicks.hpp"
#include "core/Errors.hpp"
#include "core/Svg.hpp"
#include "geometry/Apparatus.hpp"

namespace rcfd::analysis {
namespace {

constexpr double kAlphaScale = 0.65;  ///< colour scale top: about close packing
constexpr int kSnapshots = 4;

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

/// The mid-plane layer of a per-cell field, scaled to [0, 1] for the colour map; closed cells blank.
std::vector<double> layerValues(const std::vector<double>& field, const std::vector<float>& fluid,
                                const CartesianGrid& grid, int k) {
  const std::size_t n = std::size_t(grid.shape[0]) * std::size_t(grid.shape[1]);
  std::vector<double> v(n);
  for (std::size_t c = 0; c < n; ++c) {
    const std::size_t cell = std::size_t(k) * n + c;
    v[c] = fluid[cell] > 0.0f ? std::clamp(field[cell] / kAlphaScale, 0.0, 1.0) : std::nan("");
  }
  return v;
}

/// The apparatus section drawn over a panel whose left edge sits at `shift` in user x.
void drawOutline(SvgDocument& svg, const Apparatus& app, double shift) {
  for (const auto& hole : app.holes()) {
    std::vector<std::array<double, 2>> pts;
    for (const auto& p : hole) pts.push_back({p.x() + shift, p.y()});
    svg.polygon(pts, "#7f7f7f", "#000", 0.8);
  }
  for (const auto& e : app.sectionEdges()) {
    if (e.kind == BoundaryKind::Plate) continue;
    const std::string colour =
        e.kind == BoundaryKind::Inlet ? "#1f77b4" : e.kind == BoundaryKind::Outlet ? "#d62728" : "#000";
    svg.line(e.a.x() + shift, e.a.y(), e.b.x() + shift, e.b.y(), colour, e.kind == BoundaryKind::Wall ? 1.5 : 3.0);
  }
}

std::string alphaFigure(const Scene& scene, const FieldDatabase& db, const std::string& dir,
                        const std::function<bool()>& stopRequested) {
  const CartesianGrid& g = db.grid();
  const Apparatus app(scene.apparatus);
  const int k = midplaneLayer(scene, g);
  const std::vector<int> frames = snapshotFrames(db.frameCount(), kSnapshots);
  const double x0 = g.origin.x(), y0 = g.origin.y();
  const double w = g.spacing.x() * g.shape[0], h = g.spacing.y() * g.shape[1];
  const double gap = 0.12 * w, barW = 0.08 * w;
  const std::size_t panels = frames.size() + 1;
  const double panelPx = 170.0;
  const double totalW = double(panels) * (w + gap) + 3.0 * barW;
  SvgDocument svg(0.0, totalW, y0, y0 + h, panelPx / w * totalW, panelPx * h / w + 30, 45);
  auto panel = [&](const std::vector<double>& field, std::size_t p, const std::string& title) {
    const double left = double(p) * (w + gap);
    // One embedded image per panel: a few kB instead of one <rect> per cell (50 x 120 cells in quick.json).
    svg.heatmapImage(layerValues(field, db.fluidFraction(), g, k), g.shape[0], g.shape[1], left, left + w, y0, y0 + h);
    drawOutline(svg, app, left - x0);
    svg.text(left + 0.5 * w, y0 + h + 0.015 * h, title, 10, "middle");
  };
  for (std::size_t p = 0; p < frames.size(); ++p) {
    const auto f = db.frame(frames[p]);
    panel(std::vector<double>(f->alpha_p.begin(), f->alpha_p.end()), p,
          "t = " + fmt("%.3f", frames[p] * db.dtRec()) + " s");
  }
  panel(meanAlphaP(db, stopRequested), frames.size(), "time average");
  // Colour bar 0 .. kAlphaScale.
  const double bx = double(panels) * (w + gap);
  constexpr int kBarSteps = 50;
  for (int s = 0; s < kBarSteps; ++s) {
    const double a = (s + 0.5) / kBarSteps;
    svg.rect(bx, y0 + h * s / kBarSteps, bx + barW, y0 + h * (s + 1) / kBarSteps, colormap(a).hex());
  }
  svg.rect(bx, y0, bx + barW, y0 + h, "none", "#000", 0.5);
  for (const double a : {0.0, 0.2, 0.4, 0.6}) {
    svg.text(bx + 1.15 * barW, y0 + h * a / kAlphaScale, fmt("%.1f", a), 9);
  }
  svg.textPx(10, 14,
             "alpha_P in the cell layer " + std::to_string(k) + " holding the mid-plane (z = " +
                 fmt("%.4g", g.origin.z() + k * g.spacing.z()) + " .. " +
                 fmt("%.4g", g.origin.z() + (k + 1) * g.spacing.z()) + " m), " + std::to_string(db.frameCount()) +
                 " frames at dt_rec = " + fmt("%.4g", db.dtRec()) + " s",
             12);
  const std::string name = "database_alpha_p.svg";
  svg.save(dir + "/" + name);
  return name;
}


std::string pressureFigure(const PressureDropSeries& p, const std::string& dir) {
  constexpr int kTicks = 6;
  const double tEnd = p.t0 + double(p.pa.size()) * p.dt;
  double lo = *std::min_element(p.pa.begin(), p.pa.end()), hi = *std::max_element(p.pa.begin(), p.pa.end());
  if (hi - lo < 1e-9 * std::max(1.0, std::abs(hi))) {
    lo -= 1.0;
    hi += 1.0;
  }
  const double ys = niceStep((hi - lo) / kTicks), ts = niceStep((tEnd - p.t0) / kTicks);
  lo = std::floor(lo / ys) * ys;
  hi = std::ceil(hi / ys) * ys;
  const double t0 = std::floor(p.t0 / ts) * ts, t1 = std::ceil(tEnd / ts) * ts;
  SvgDocument svg(t0, t1, lo, hi, 720, 320, 55);
  svg.axes("time after the start of sampling [s]", "pressure drop [Pa]", int(std::lround((t1 - t0) / ts)),
           int(std::lround((hi - lo) / ys)));
  std::vector<std::array<double, 2>> pts;
  pts.reserve(p.pa.size());
  double mean = 0.0;
  for (std::size_t i = 0; i < p.pa.size(); ++i) {
    pts.push_back({p.t0 + double(i) * p.dt, p.pa[i]});
    mean += p.pa[i];
  }
  mean /= double(p.pa.size());
  svg.polyline(pts, "#1f4e99", 1.0);
  svg.line(p.t0, mean, tEnd, mean, "#d62728", 1.0, "5,4");
  svg.textPx(60, 16,
             "Bed pressure drop (inlet - outlet); dashed: mean " + fmt("%.1f", mean) + " Pa; dominant frequency " +
                 (p.dominantFrequency ? fmt("%.2f", *p.dominantFrequency) + " Hz" : std::string("none")),
             12);
  const std::string name = "database_pressure_drop.svg";
  svg.save(dir + "/" + name);
  return name;
}

}  // namespace

std::vector<double> meanAlphaP(const FieldDatabase& db, const std::function<bool()>& stopRequested) {
  std::vector<double> sum(std::size_t(db.grid().cellCount()), 0.0);
  for (int n = 0; n < db.frameCount(); ++n) {
    if (stopRequested && stopRequested())
      throw Cancelled("stopped while averaging alpha_P over the frames (frame " + std::to_string(n) + " of " +
                      std::to_string(db.frameCount()) + ")");
    const auto f = db.frame(n);
    for (std::size_t c = 0; c < sum.size(); ++c) sum[c] += f->alpha_p[c];
  }
  for (double& s : sum) s /= std::max(1, db.frameCount());
  return sum;
}

std::vector<int> snapshotFrames(int frameCount, int count) {
  std::vector<int> out;
  if (frameCount <= 0 || count <= 0) return out;
  count = std::min(count, frameCount);
  for (int s = 0; s < count; ++s) {
    out.push_back(count == 1 ? 0 : int(std::lround(double(s) * (frameCount - 1) / (count - 1))));
  }
  return out;
}

std::vector<std::string> writeDatabaseFigures(const Scene& scene, const FieldDatabase& db,
                                              const PressureDropSeries& pressureDrop, const std::string& outDir,
                                              const std::function<bool()>& stopRequested) {
  std::vector<std::string> names{alphaFigure(scene, db, outDir, stopRequested)};
  if (!pressureDrop.pa.empty() && pressureDrop.dt > 0.0) names.push_back(pressureFigure(pressureDrop, outDir));
  return names;
}

}  // namespace rcfd::analysis
