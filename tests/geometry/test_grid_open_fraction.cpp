// makeGrid() and openFractions(): cell counts, the total open volume against the analytic chamber
// volume, and single cells against Monte Carlo estimates with contains().

#include <gtest/gtest.h>

#include <random>

#include "GeometryFixtures.hpp"
#include "geometry/Apparatus.hpp"

namespace rcfd {
namespace {

using Eigen::Vector3d;

double gridOpenVolume(const CartesianGrid& g, const std::vector<double>& f) {
  double v = 0.0;
  for (double x : f) v += x * g.cellVolume();
  return v;
}

TEST(Grid, WholeNumberOfCellsSpansEachExtent) {
  const Apparatus app(test::procellSpec(false));
  GridSpec spec;
  spec.cell_size = Vector3d::Constant(0.005);
  CartesianGrid g = makeGrid(app, spec);
  EXPECT_EQ(g.shape, (std::array<int, 3>{50, 120, 40}));
  EXPECT_NEAR(g.spacing.x(), 0.005, 1e-15);
  EXPECT_EQ(g.origin, app.lowerCorner());
  EXPECT_LT((g.upperCorner() - app.upperCorner()).norm(), 1e-15);
  spec.cell_size = Vector3d(0.007, 0.011, 0.03);  // 35.7 -> 36, 54.5 -> 55, 6.67 -> 7
  g = makeGrid(app, spec);
  EXPECT_EQ(g.shape, (std::array<int, 3>{36, 55, 7}));
  EXPECT_NEAR(g.spacing.x() * 36, 0.25, 1e-15);
  EXPECT_NEAR(g.spacing.z() * 7, 0.2, 1e-15);
  spec.cell_size = Vector3d::Constant(5.0);  // larger than the apparatus: one cell
  EXPECT_EQ(makeGrid(app, spec).shape, (std::array<int, 3>{1, 1, 1}));
  spec.cell_size = Vector3d(0.005, 0.0, 0.005);
  EXPECT_EQ(test::violationPointers([&] { makeGrid(app, spec); }), std::vector<std::string>{"/grid/cell_size"});
}

TEST(Grid, TotalOpenVolumeEqualsTheChamberVolume) {
  // Clipping is exact, so the sum matches the analytic volume to round-off (summing ~1e6 cells costs
  // ~1e-11 relative; the requirement was 0.5%).
  for (bool withPlates : {false, true}) {
    const Apparatus app(test::procellSpec(withPlates));
    for (double h : {0.0025, 0.005, 0.0073, 0.01, 0.031}) {
      GridSpec spec;
      spec.cell_size = Vector3d(h, h, withPlates ? 0.2 : h);
      const CartesianGrid g = makeGrid(app, spec);
      const auto f = openFractions(app, g);
      ASSERT_EQ(std::int64_t(f.size()), g.cellCount());
      for (double x : f) ASSERT_TRUE(x >= 0.0 && x <= 1.0);
      EXPECT_NEAR(gridOpenVolume(g, f) / app.openVolume(), 1.0, 1e-10) << "cell " << h;
    }
  }
  const Apparatus box(test::boxSpec(0.1, 0.2, 0.3, false));
  GridSpec spec;
  spec.cell_size = Vector3d::Constant(0.01);
  const CartesianGrid g = makeGrid(box, spec);
  const auto f = openFractions(box, g);
  for (double x : f) ASSERT_EQ(x, 1.0);
  EXPECT_EQ(g.cellCount(), 10 * 20 * 30);
  EXPECT_NEAR(gridOpenVolume(g, f), box.openVolume(), 1e-15);
}

TEST(Grid, PlateCellsAreClosedAndFreeCellsOpen) {
  // A 0.5 mm grid aligns with the plate faces (x = 0.0225..0.0245 m is 295..299 cells from -0.125).
  const Apparatus app(test::procellSpec(true));
  GridSpec spec;
  spec.cell_size = Vector3d(0.0005, 0.0005, 0.2);
  const CartesianGrid g = makeGrid(app, spec);
  const auto f = openFractions(app, g);
  const auto inPlate = g.cellOf({0.0235, 0.06, 0.1});
  EXPECT_EQ(f[std::size_t(g.flatIndex(inPlate[0], inPlate[1], 0))], 0.0);
  const auto beside = g.cellOf({0.0220, 0.06, 0.1});
  EXPECT_EQ(f[std::size_t(g.flatIndex(beside[0], beside[1], 0))], 1.0);
  const auto belowV = g.cellOf({0.1, 0.05, 0.1});
  EXPECT_EQ(f[std::size_t(g.flatIndex(belowV[0], belowV[1], 0))], 0.0);
  const auto center = g.cellOf({0.0, 0.3, 0.1});
  EXPECT_EQ(f[std::size_t(g.flatIndex(center[0], center[1], 0))], 1.0);
}

TEST(Grid, CutCellsMatchMonteCarlo) {
  // Cells cut by the V walls, the inlet corner and a plate tip against sampling with contains().
  const Apparatus app(test::procellSpec(true));
  GridSpec spec;
  spec.cell_size = Vector3d(0.0073, 0.0073, 0.0073);
  const CartesianGrid g = makeGrid(app, spec);
  const auto f = openFractions(app, g);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (const Vector3d& probe : {Vector3d(0.011, 0.001, 0.1), Vector3d(0.06, 0.09, 0.05),
                               Vector3d(-0.1, 0.16, 0.199), Vector3d(0.024, 0.095, 0.1),
                               Vector3d(-0.023, 0.036, 0.1), Vector3d(0.124, 0.2, 0.001)}) {
    const auto c = g.cellOf(probe);
    const double exact = f[std::size_t(g.flatIndex(c[0], c[1], c[2]))];
    const Vector3d lo = g.origin + g.spacing.cwiseProduct(Vector3d(c[0], c[1], c[2]));
    constexpr int kSamples = 200'000;
    int in = 0;
    for (int s = 0; s < kSamples; ++s)
      in += app.contains(lo + g.spacing.cwiseProduct(Vector3d(u(rng), u(rng), u(rng))));
    const double mc = double(in) / kSamples;
    const double sigma = std::sqrt(std::max(mc * (1 - mc), 1e-6) / kSamples);
    EXPECT_NEAR(exact, mc, 5 * sigma + 1e-9) << "cell at " << probe.transpose();
    // The probes sit in cut cells, where clipping matters.
    EXPECT_TRUE(exact > 0.0 && exact < 1.0) << "probe " << probe.transpose() << " fraction " << exact;
  }
}

}  // namespace
}  // namespace rcfd
