// Completion of u_P (and its spread) where a frame holds no particle velocity (VelocityCompletion.hpp).

#include "fields/VelocityCompletion.hpp"

#include <array>

namespace rcfd {

namespace {

/// What one completed cell receives: sums over its neighbours, weighted by particle volume.
struct Completion {
  std::int64_t cell = 0;
  double weight = 0.0, upWeight = 0.0, downWeight = 0.0;
  std::array<double, 3> u{}, variance{}, up{}, down{};
};

}  // namespace

std::vector<char> cellsWithParticleVolume(const FieldFrame& frame) {
  std::vector<char> holds(frame.alpha_p.size());
  for (std::size_t c = 0; c < holds.size(); ++c) holds[c] = frame.alpha_p[c] > 0.0f;
  return holds;
}

std::int64_t completeParticleVelocity(const CartesianGrid& grid, const std::vector<float>& openFraction,
                                      std::vector<char> holdsVelocity, FieldFrame& frame, int layers) {
  const int nx = grid.shape[0], ny = grid.shape[1], nz = grid.shape[2];
  const bool spread = frame.hasVelocitySpread();
  std::int64_t completed = 0;
  std::vector<Completion> layer;
  for (int pass = 0; pass < layers; ++pass) {
    layer.clear();
    for (int k = 0; k < nz; ++k) {
      for (int j = 0; j < ny; ++j) {
        for (int i = 0; i < nx; ++i) {
          const std::int64_t c = grid.flatIndex(i, j, k);
          if (holdsVelocity[std::size_t(c)] || !(openFraction[std::size_t(c)] > 0.0f)) continue;
          Completion s;
          s.cell = c;
          for (int dk = -1; dk <= 1; ++dk) {
            if (k + dk < 0 || k + dk >= nz) continue;
            for (int dj = -1; dj <= 1; ++dj) {
              if (j + dj < 0 || j + dj >= ny) continue;
              for (int di = -1; di <= 1; ++di) {
                if (i + di < 0 || i + di >= nx || (di == 0 && dj == 0 && dk == 0)) continue;
                const auto n = std::size_t(grid.flatIndex(i + di, j + dj, k + dk));
                if (!holdsVelocity[n]) continue;
                const double w = double(frame.alpha_p[n]) * double(openFraction[n]);
                if (!(w > 0.0)) continue;
                s.weight += w;
                for (int d = 0; d < 3; ++d) s.u[std::size_t(d)] += w * frame.u_p[3 * n + std::size_t(d)];
                if (!spread) continue;
                const double f = frame.up_fraction[n];
                s.upWeight += w * f;
                s.downWeight += w * (1.0 - f);
                for (int d = 0; d < 3; ++d) {
                  const std::size_t v = 3 * n + std::size_t(d);
                  s.variance[std::size_t(d)] += w * frame.u_p_variance[v];
                  s.up[std::size_t(d)] += w * f * frame.u_p_up[v];
                  s.down[std::size_t(d)] += w * (1.0 - f) * frame.u_p_down[v];
                }
              }
            }
          }
          if (s.weight > 0.0) layer.push_back(s);
        }
      }
    }
    if (layer.empty()) break;
    // Written after the whole layer is found: a cell completed in this pass does not feed another
    // cell of the same pass, so the result does not depend on the sweep's order.
    for (const Completion& s : layer) {
      const auto c = std::size_t(s.cell);
      std::array<double, 3> u;
      for (int d = 0; d < 3; ++d) u[std::size_t(d)] = s.u[std::size_t(d)] / s.weight;
      for (int d = 0; d < 3; ++d) frame.u_p[3 * c + std::size_t(d)] = float(u[std::size_t(d)]);
      holdsVelocity[c] = 1;
      if (!spread) continue;
      frame.up_fraction[c] = float(s.upWeight / s.weight);
      for (int d = 0; d < 3; ++d) {
        const std::size_t v = 3 * c + std::size_t(d);
        frame.u_p_variance[v] = float(s.variance[std::size_t(d)] / s.weight);
        // u_P where a stream has no volume (docs/formats.md).
        frame.u_p_up[v] = float(s.upWeight > 0.0 ? s.up[std::size_t(d)] / s.upWeight : u[std::size_t(d)]);
        frame.u_p_down[v] = float(s.downWeight > 0.0 ? s.down[std::size_t(d)] / s.downWeight : u[std::size_t(d)]);
      }
    }
    completed += std::int64_t(layer.size());
  }
  // Out of reach of any particle volume: no velocity, whatever the file held there.
  for (std::size_t c = 0; c < holdsVelocity.size(); ++c) {
    if (holdsVelocity[c] || !(openFraction[c] > 0.0f)) continue;
    for (int d = 0; d < 3; ++d) frame.u_p[3 * c + std::size_t(d)] = 0.0f;
    if (!spread) continue;
    frame.up_fraction[c] = 0.0f;
    for (int d = 0; d < 3; ++d) {
      frame.u_p_up[3 * c + std::size_t(d)] = frame.u_p_down[3 * c + std::size_t(d)] = 0.0f;
      frame.u_p_variance[3 * c + std::size_t(d)] = 0.0f;
    }
  }
  return completed;
}

}  // namespace rcfd
