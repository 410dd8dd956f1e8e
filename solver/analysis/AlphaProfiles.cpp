#include "analysis/AlphaProfiles.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "analysis/CalibrationReport.hpp"
#include "core/Svg.hpp"

namespace rcfd::analysis {

std::vector<AlphaProfile> alphaProfiles(const Scene& scene, const FieldDatabase& db, const std::vector<double>& alpha,
                                        const std::vector<double>& heights) {
  const CartesianGrid& g = db.grid();
  const auto& open = db.fluidFraction();
  const int mid = midplaneLayer(scene, g);
  std::vector<AlphaProfile> out;
  for (const double y : heights) {
    const int j = int(std::floor((y - g.origin.y()) / g.spacing.y()));
    if (j < 0 || j >= g.shape[1]) continue;
    AlphaProfile p;
    p.y = g.cellCenter(0, j, 0).y();
    for (int i = 0; i < g.shape[0]; ++i) {
      const std::size_t m = std::size_t(g.flatIndex(i, j, mid));
      if (open[m] <= 0.0f) continue;
      double sum = 0.0, vol = 0.0;
      for (int k = 0; k < g.shape[2]; ++k) {
        const std::size_t c = std::size_t(g.flatIndex(i, j, k));
        sum += open[c] * alpha[c];
        vol += open[c];
      }
      p.cells.push_back({g.cellCenter(i, j, mid).x(), alpha[m], sum / vol, open[m]});
    }
    out.push_back(std::move(p));
  }
  return out;
}

std::string writeAlphaProfileFigure(const std::vector<AlphaProfile>& profiles, const std::string& outDir) {
  constexpr double kAlphaTop = 0.7, kAnnulusBound = 0.5;
  const std::vector<std::string> colours{"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b"};
  double x0 = 0.0, x1 = 0.0;
  for (const auto& p : profiles)
    for (const auto& c : p.cells) x0 = std::min(x0, c.x), x1 = std::max(x1, c.x);
  if (x1 <= x0) x1 = x0 + 1.0;
  SvgDocument svg(x0, x1, 0.0, kAlphaTop, 720, 360, 55);
  svg.axes("x [m]", "time-averaged alpha_P (mid-plane layer)", 10, 7);
  svg.line(x0, kAnnulusBound, x1, kAnnulusBound, "#7f7f7f", 1.0, "5,4");
  for (std::size_t n = 0; n < profiles.size(); ++n) {
    const std::string& colour = colours[n % colours.size()];
    std::vector<std::array<double, 2>> pts;
    for (const auto& c : profiles[n].cells) {
      pts.push_back({c.x, c.alphaMid});
      if (c.openMid < 1.0) svg.circle(c.x, c.alphaMid, 3.0, colour);  // a cut wall cell
    }
    svg.polyline(pts, colour, 1.5);
    char label[64];
    std::snprintf(label, sizeof label, "y = %.4f m", profiles[n].y);
    svg.text(x0 + 0.02 * (x1 - x0), kAlphaTop * (0.96 - 0.05 * double(n)), label, 11, "start", colour);
  }
  svg.textPx(10, 14, "alpha_P across x at the rows of the given heights; dots: cells cut by a wall; dashed: 0.5", 12);
  const std::string name = "database_alpha_p_profiles.svg";
  svg.save(outDir + "/" + name);
  return name;
}

}  // namespace rcfd::analysis
