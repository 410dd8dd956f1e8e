// The particle velocity where a frame holds no particle volume (VelocityCompletion.hpp).
#include <gtest/gtest.h>

#include "fields/VelocityCompletion.hpp"

namespace rcfd {
using Vec3 = Eigen::Vector3d;

namespace {

/// A 4 x 3 x 1 grid of 1 cm cells, every cell open but the last.
struct Slab {
  CartesianGrid grid;
  std::vector<float> open;
  FieldFrame frame;

  explicit Slab(bool spread) {
    grid.origin = Vec3::Zero();
    grid.spacing = Vec3(0.01, 0.01, 0.01);
    grid.shape = {4, 3, 1};
    const auto n = std::size_t(grid.cellCount());
    open.assign(n, 1.0f);
    open[n - 1] = 0.0f;
    frame.alpha_p.assign(n, 0.0f);
    frame.u_p.assign(3 * n, 0.0f);
    frame.u_g.assign(3 * n, 0.0f);
    if (spread) {
      frame.up_fraction.assign(n, 0.0f);
      frame.u_p_up.assign(3 * n, 0.0f);
      frame.u_p_down.assign(3 * n, 0.0f);
      frame.u_p_variance.assign(3 * n, 0.0f);
    }
  }
  std::size_t cell(int i, int j) const { return std::size_t(grid.flatIndex(i, j, 0)); }
  void occupy(int i, int j, float alpha, Vec3 u, float up = 0.0f, Vec3 uUp = Vec3::Zero(), Vec3 uDown = Vec3::Zero(),
              float variance = 0.0f) {
    const std::size_t c = cell(i, j);
    frame.alpha_p[c] = alpha;
    for (int d = 0; d < 3; ++d) frame.u_p[3 * c + std::size_t(d)] = float(u[d]);
    if (!frame.hasVelocitySpread()) return;
    frame.up_fraction[c] = up;
    for (int d = 0; d < 3; ++d) {
      frame.u_p_up[3 * c + std::size_t(d)] = float(uUp[d]);
      frame.u_p_down[3 * c + std::size_t(d)] = float(uDown[d]);
      frame.u_p_variance[3 * c + std::size_t(d)] = variance * float(d + 1);
    }
  }
};

TEST(VelocityCompletion, AnEmptyCellTakesTheVolumeWeightedVelocityOfItsNeighbours) {
  Slab s(false);
  s.occupy(0, 0, 0.3f, Vec3(1.0, 2.0, 0.0));
  s.occupy(1, 1, 0.1f, Vec3(-1.0, 6.0, 0.5));
  s.frame.u_p[3 * s.cell(3, 0)] = 7.0f;  // what a file may hold where there are no particles
  const FieldFrame before = s.frame;
  const auto completed = completeParticleVelocity(s.grid, s.open, cellsWithParticleVolume(s.frame), s.frame, 1);
  // Cell (1, 0) touches both: (0.3 (1, 2, 0) + 0.1 (-1, 6, 0.5)) / 0.4.
  const std::size_t both = s.cell(1, 0);
  EXPECT_FLOAT_EQ(s.frame.u_p[3 * both], 0.5f);
  EXPECT_FLOAT_EQ(s.frame.u_p[3 * both + 1], 3.0f);
  EXPECT_FLOAT_EQ(s.frame.u_p[3 * both + 2], 0.125f);
  // Cell (2, 2) touches (1, 1) only; (3, 0) and (3, 1) touch nothing occupied and have no velocity.
  EXPECT_FLOAT_EQ(s.frame.u_p[3 * s.cell(2, 2) + 1], 6.0f);
  for (const auto c : {s.cell(3, 0), s.cell(3, 1)})
    for (int d = 0; d < 3; ++d) EXPECT_EQ(s.frame.u_p[3 * c + std::size_t(d)], 0.0f);
  // The solid cell (3, 2) stays 0; occupied cells and alpha_P are untouched.
  for (int d = 0; d < 3; ++d) EXPECT_EQ(s.frame.u_p[3 * s.cell(3, 2) + std::size_t(d)], 0.0f);
  for (const auto c : {s.cell(0, 0), s.cell(1, 1)})
    for (int d = 0; d < 3; ++d) EXPECT_EQ(s.frame.u_p[3 * c + std::size_t(d)], before.u_p[3 * c + std::size_t(d)]);
  EXPECT_EQ(s.frame.alpha_p, before.alpha_p);
  // Occupied cells 2, touching one of them: the other 12 - 2 - 1 solid - 2 out of reach.
  EXPECT_EQ(completed, 7);
}

TEST(VelocityCompletion, OneLayerReachesNoFartherAndLayersPassOnOnlyThroughVolume) {
  // The reader's rule: a completed empty cell (alpha_P = 0) passes nothing on, whatever the layers.
  Slab s(false);
  s.occupy(0, 0, 0.2f, Vec3(0.0, 1.0, 0.0));
  completeParticleVelocity(s.grid, s.open, cellsWithParticleVolume(s.frame), s.frame, 3);
  EXPECT_FLOAT_EQ(s.frame.u_p[3 * s.cell(1, 1) + 1], 1.0f);
  EXPECT_EQ(s.frame.u_p[3 * s.cell(2, 0) + 1], 0.0f);
  // The database job's rule: cells the smoothing gave volume but no parcel are completed outward,
  // each layer from the one before.
  Slab t(false);
  t.occupy(0, 0, 0.2f, Vec3(0.0, 1.0, 0.0));
  t.occupy(1, 0, 0.05f, Vec3::Zero());
  t.occupy(2, 0, 0.01f, Vec3::Zero());
  std::vector<char> parcels(t.frame.alpha_p.size(), 0);
  parcels[t.cell(0, 0)] = 1;
  completeParticleVelocity(t.grid, t.open, parcels, t.frame, 1);
  EXPECT_FLOAT_EQ(t.frame.u_p[3 * t.cell(1, 0) + 1], 1.0f);
  EXPECT_EQ(t.frame.u_p[3 * t.cell(2, 0) + 1], 0.0f);
  completeParticleVelocity(t.grid, t.open, parcels, t.frame, 2);
  EXPECT_FLOAT_EQ(t.frame.u_p[3 * t.cell(2, 0) + 1], 1.0f);
}

TEST(VelocityCompletion, TheSpreadIsCompletedSoThatTheStreamsStillAddUpToTheMean) {
  Slab s(true);
  // Two cells: 0.3 of volume, a quarter rising at 2 m/s, the rest falling at -2/3 (mean 0); and 0.1
  // of volume, all rising at 1 m/s.
  s.occupy(0, 0, 0.3f, Vec3(0.0, 0.0, 0.0), 0.25f, Vec3(0.0, 2.0, 0.0), Vec3(0.0, -2.0 / 3.0, 0.0), 0.4f);
  s.occupy(0, 1, 0.1f, Vec3(0.0, 1.0, 0.0), 1.0f, Vec3(0.0, 1.0, 0.0), Vec3(0.0, 1.0, 0.0), 0.2f);
  completeParticleVelocity(s.grid, s.open, cellsWithParticleVolume(s.frame), s.frame, 1);
  const std::size_t c = s.cell(1, 0);
  const float f = s.frame.up_fraction[c];
  EXPECT_FLOAT_EQ(f, (0.3f * 0.25f + 0.1f) / 0.4f);
  EXPECT_FLOAT_EQ(s.frame.u_p[3 * c + 1], 0.25f);
  EXPECT_NEAR(f * s.frame.u_p_up[3 * c + 1] + (1.0f - f) * s.frame.u_p_down[3 * c + 1], s.frame.u_p[3 * c + 1], 1e-6);
  // Only the first cell has a downward stream: the completed one has its velocity.
  EXPECT_FLOAT_EQ(s.frame.u_p_down[3 * c + 1], -2.0f / 3.0f);
  EXPECT_FLOAT_EQ(s.frame.u_p_variance[3 * c + 1], (0.3f * 0.8f + 0.1f * 0.4f) / 0.4f);
}

}  // namespace
}  // namespace rcfd
