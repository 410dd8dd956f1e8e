// nearHalfSpaceMasks(): a half-space left out of a cell's mask is one that no short move from any point
// of the cell can come within the margin of, so the motion kernel may skip its test; and the masks
// leave out most planes (else they would save nothing).

#include <gtest/gtest.h>

#include <bit>
#include <random>

#include "GeometryFixtures.hpp"
#include "geometry/Apparatus.hpp"
#include "geometry/WallClearance.hpp"

namespace rcfd {
namespace {

using Eigen::Vector3d;

TEST(NearHalfSpaces, ALeftOutPlaneIsClearedByEveryShortMoveFromTheCell) {
  const Apparatus app(test::procellSpec(false));
  GridSpec spec;
  spec.cell_size = Vector3d(0.005, 0.007, 0.006);  // unequal spacings: the half diagonal is not a cube's
  const CartesianGrid grid = makeGrid(app, spec);
  const auto planes = app.convexHalfSpaces();
  const double margin = 2.0 * app.boundaryTolerance();
  const double reach = 1.5 * grid.spacing.minCoeff();
  const auto masks = nearHalfSpaceMasks(planes, grid, margin, reach);
  ASSERT_EQ(masks.size(), std::size_t(grid.cellCount()));

  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(0.0, 1.0), sym(-1.0, 1.0);
  std::uniform_int_distribution<std::int64_t> anyCell(0, grid.cellCount() - 1);
  int checked = 0, closest = 0;
  double tightest = 1e300;
  for (int trial = 0; trial < 200000; ++trial) {
    const std::int64_t c = anyCell(rng);
    const auto ijk = grid.cellIjk(c);
    // A point anywhere in the cell, corners included, and a move of length up to `reach`.
    Vector3d p;
    for (int d = 0; d < 3; ++d) {
      const double f = trial % 4 == 0 ? double(rng() & 1) : unit(rng);
      p[d] = grid.origin[d] + (double(ijk[std::size_t(d)]) + f) * grid.spacing[d];
    }
    Vector3d dir(sym(rng), sym(rng), sym(rng));
    if (dir.norm() < 1e-3) continue;
    const Vector3d end = p + reach * (trial % 3 == 0 ? 1.0 : unit(rng)) * dir.normalized();
    for (std::size_t j = 0; j < planes.size(); ++j) {
      if (masks[std::size_t(c)] >> j & 1u) continue;
      const double g = planes[j].n.x() * end.x() + planes[j].n.y() * end.y() + planes[j].n.z() * end.z() - planes[j].c;
      ASSERT_GE(g, margin) << "cell " << c << ", plane " << j;
      ++checked;
      if (g < tightest) tightest = g, closest = int(j);
    }
  }
  EXPECT_GT(checked, 100000);
  // The bound is not loose by more than a cell diagonal and the reach (else the masks would keep planes
  // a move cannot reach, and skip less than they could).
  EXPECT_LT(tightest, 2.0 * grid.spacing.norm() + reach) << "plane " << closest;
}

TEST(NearHalfSpaces, MostCellsNeedFewOfThePlanes) {
  const Apparatus app(test::procellSpec(false));
  GridSpec spec;
  spec.cell_size = Vector3d::Constant(0.005);
  const CartesianGrid grid = makeGrid(app, spec);
  const auto planes = app.convexHalfSpaces();
  ASSERT_EQ(planes.size(), 8u);  // the outline's six edges and the two z walls
  const auto masks = nearHalfSpaceMasks(planes, grid, 2.0 * app.boundaryTolerance(), 0.0075);
  std::int64_t none = 0, planesKept = 0;
  for (const std::uint32_t m : masks) {
    none += m == 0;
    planesKept += std::popcount(m);
  }
  // A plane is kept within about 2.4 cells of it: the 40-cell depth keeps the z walls in 4 layers of 40,
  // and the interior of the chamber needs none.
  EXPECT_GT(double(none) / double(masks.size()), 0.5);
  EXPECT_LT(double(planesKept) / double(masks.size()), 1.0);
  // Every cell touching a wall keeps that wall: the corner cell at the bottom of the V keeps the inlet,
  // a V wall and the front z wall.
  EXPECT_NE(masks[0], 0u);
  EXPECT_THROW(nearHalfSpaceMasks(std::vector<Apparatus::HalfSpace>(33), grid, 0.0, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace rcfd
