#include "analysis/AlphaProfiles.hpp"

#include <cmath>

#include "analysis/CalibrationReport.hpp"

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

}  // namespace rcfd::analysis
