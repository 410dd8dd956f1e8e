// How far the particles in the spray zone move between two frames (FrameSpacing.hpp).

#include "analysis/FrameSpacing.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <spdlog/fmt/fmt.h>

namespace rcfd {

namespace {

/// The speed below which `share` of the weight lies (samples sorted by speed).
double weightedQuantile(std::vector<std::pair<double, double>>& samples, double total, double share) {
  double below = 0.0;
  for (const auto& [speed, weight] : samples) {
    below += weight;
    if (below >= share * total) return speed;
  }
  return samples.empty() ? 0.0 : samples.back().first;
}

}  // namespace

FrameSpacing frameSpacing(const FieldDatabase& database, const SprayZone& zone, int maxFrames) {
  FrameSpacing out;
  out.dtRec = database.dtRec();
  const CartesianGrid& grid = database.grid();
  std::vector<std::size_t> cells;
  for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
    const auto ijk = grid.cellIjk(c);
    if (zone.contains(grid.cellCenter(ijk[0], ijk[1], ijk[2]))) cells.push_back(std::size_t(c));
  }
  out.zoneCells = std::int64_t(cells.size());
  const int frames = database.frameCount();
  const int stride = std::max(1, frames / std::max(1, maxFrames));
  std::vector<std::pair<double, double>> samples;  // (speed, particle volume fraction)
  double total = 0.0;
  for (int n = 0; n < frames; n += stride) {
    const auto frame = database.frame(n);
    ++out.framesSampled;
    for (const std::size_t c : cells) {
      const double alpha = frame->alpha_p[c];
      if (!(alpha > 0.0)) continue;
      double speed2 = 0.0;
      for (int d = 0; d < 3; ++d) {
        const double v = frame->u_p[3 * c + std::size_t(d)];
        speed2 += v * v;
      }
      samples.emplace_back(std::sqrt(speed2), alpha);
      total += alpha;
    }
  }
  if (!(total > 0.0)) return out;
  std::sort(samples.begin(), samples.end());
  out.medianSpeed = weightedQuantile(samples, total, 0.5);
  out.p90Speed = weightedQuantile(samples, total, 0.9);
  out.cellsPerFrame = out.medianSpeed * out.dtRec / grid.spacing.minCoeff();
  return out;
}

nlohmann::json toJson(const FrameSpacing& s) {
  return {{"dt_rec_s", s.dtRec},
          {"zone_speed_median_m_s", s.medianSpeed},
          {"zone_speed_p90_m_s", s.p90Speed},
          {"cells_per_frame", s.cellsPerFrame},
          {"sparse", s.sparse()},
          {"frames_sampled", s.framesSampled},
          {"zone_cells", s.zoneCells}};
}

std::string sparseFramesWarning(const FrameSpacing& s) {
  if (!s.sparse()) return {};
  return fmt::format(
      "the database's frames are {:.3g} s apart: the particles in the spray zone move {:.1f} cells between two "
      "(median speed {:.2f} m/s), more than {:.0f}; the tracers see the flow frozen between frames and their "
      "spray-zone stays come out long, their crossings rare (docs/accuracy.md, \"Between frames\"): a database "
      "sampled every {:.3g} s or less avoids it",
      s.dtRec, s.cellsPerFrame, s.medianSpeed, kSparseCellsPerFrame,
      s.dtRec * kSparseCellsPerFrame / std::max(s.cellsPerFrame, 1e-300));
}

}  // namespace rcfd
