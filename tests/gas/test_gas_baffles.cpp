// Draft plates thinner than a cell as baffles in the gas phase: the quick slice (2 mm plates inside
// 5 mm cell columns, the slot jet between them). No gas crosses the plates' faces, the jet goes up the
// channel between the plates and around their upper edges, and Eq. (1) holds every step.

#include <gtest/gtest.h>

#include <cmath>

#include "GasTestSupport.hpp"
#include "cfddem/gas/FaceApertures.hpp"

namespace rcfd {
namespace {

using test::GasCase;
using test::quickSliceScene;

// Grid of the quick slice: x from -0.125 m, 5 mm cells. The right plate (x 0.0225..0.0245) lies in
// column 29 and closes the face x = 0.025 (index 30); the left one closes x = -0.025 (index 20). The
// plates span y 0.035..0.095: rows 7..18.
constexpr int kRightBaffle = 30, kLeftBaffle = 20, kFirstRow = 7, kLastRow = 18;

/// Index of face (i, j, k) of axis d in the layout of FaceApertures.
std::size_t face(const gas::FaceApertures& ap, int d, int i, int j, int k) {
  const auto& s = ap.shape[std::size_t(d)];
  return (std::size_t(k) * s[1] + j) * s[0] + i;
}

TEST(GasBaffles, ThinPlatesCloseTheirNearestFacesOnly) {
  GasCase c(quickSliceScene(true));
  const auto& g = *c.solver;
  const auto& ap = g.apertures();
  const int nz = c.grid.shape[2];
  for (int k = 0; k < nz; ++k)
    for (int j = kFirstRow; j <= kLastRow; ++j) {
      for (int i : {kLeftBaffle, kRightBaffle}) {
        const std::size_t f = face(ap, 0, i, j, k);
        EXPECT_EQ(ap.open[0][f], 0.0);
        EXPECT_EQ(g.faceKinds(0)[f], gas::GasSolver::Closed);
      }
      // The other face of each plate column stays open; the column is cut by the plate (phi 0.6).
      EXPECT_EQ(ap.open[0][face(ap, 0, kRightBaffle - 1, j, k)], 1.0);
      EXPECT_NEAR(g.openFraction()[std::size_t(c.grid.flatIndex(kRightBaffle - 1, j, k))], 0.6, 1e-12);
    }
  // Above and below the plates the faces are open.
  EXPECT_EQ(ap.open[0][face(ap, 0, kRightBaffle, kLastRow + 1, 1)], 1.0);
  EXPECT_EQ(ap.open[0][face(ap, 0, kRightBaffle, kFirstRow - 1, 1)], 1.0);

  // A tip half-way up a row closes half of that face: the aperture is exact.
  Scene s = quickSliceScene(true);
  s.apparatus.draft_plates->height = 0.0625;  // upper edge at 0.0975
  const Apparatus app(s.apparatus);
  const auto tip = gas::computeFaceApertures(app, makeGrid(app, s.grid));
  EXPECT_NEAR(tip.open[0][face(tip, 0, kRightBaffle, kLastRow + 1, 1)], 0.5, 1e-12);
}

/// Upward volume flux through the y-faces of row j for cells i0..i1 [m3/s] (alpha_G = 1 here).
double upwardFlux(const GasCase& c, int j, int i0, int i1) {
  const auto& g = *c.solver;
  const auto& ap = g.apertures();
  const double area = c.grid.spacing.x() * c.grid.spacing.z();
  double q = 0.0;
  for (int k = 0; k < c.grid.shape[2]; ++k)
    for (int i = i0; i <= i1; ++i) {
      const std::size_t f = face(ap, 1, i, j, k);
      q += area * ap.open[1][f] * g.faceVelocity(1)[f];
    }
  return q;
}

TEST(GasBaffles, NoFluxThroughThePlatesTheJetGoesAroundThem) {
  GasCase c(quickSliceScene(true));
  auto& g = *c.solver;
  const double qTotal = c.scene.process.gas_flow_rate + c.scene.process.atomisation_flow_rate;
  const double hy = c.grid.spacing.y(), hz = c.grid.spacing.z();
  for (int n = 0; n < 20; ++n) {
    g.step(1.0);
    ASSERT_LE(g.lastStep().divergence.relative, c.scene.gas.pressure_tolerance) << "step " << n;
    ASSERT_NEAR(g.netOutflow(), g.nozzleFlow(), 1e-7 * qTotal) << "step " << n;
  }
  // No gas through the baffle faces.
  double through = 0.0;
  for (int k = 0; k < c.grid.shape[2]; ++k)
    for (int j = kFirstRow; j <= kLastRow; ++j)
      for (int i : {kLeftBaffle, kRightBaffle})
        through += std::abs(g.faceVelocity(0)[face(g.apertures(), 0, i, j, k)]) * hy * hz;
  EXPECT_EQ(through, 0.0);
  // So the channel between the plates (cells 20..29) carries the same upward flow at every row along
  // the plates: what the jet brings in at the lower edges leaves over the upper edges. Without the
  // baffles (measured on this set-up) 0.0030 m3/s crossed the plates' faces and the channel flow fell
  // from 0.0057 to 0.0028 m3/s along them.
  const double q0 = upwardFlux(c, kFirstRow + 1, kLeftBaffle, kRightBaffle - 1);
  EXPECT_GT(q0, 0.5 * c.scene.process.gas_flow_rate);
  for (int j = kFirstRow + 2; j <= kLastRow; ++j)
    EXPECT_NEAR(upwardFlux(c, j, kLeftBaffle, kRightBaffle - 1), q0, 1e-6 * qTotal) << "row " << j;
  // Around the upper edges the gas leaves the channel outwards (the open faces just above the plates).
  double sideways = 0.0;
  for (int k = 0; k < c.grid.shape[2]; ++k)
    sideways += g.faceVelocity(0)[face(g.apertures(), 0, kRightBaffle, kLastRow + 1, k)] -
                g.faceVelocity(0)[face(g.apertures(), 0, kLeftBaffle, kLastRow + 1, k)];
  EXPECT_GT(sideways, 0.0);
}

// A plate of 10 um in a uniform stream (a box with frictionless side and front/back walls, uniform
// inflow at the bottom): the baffle is a no-slip wall on both sides, as the outer walls. Without the
// plates the uniform stream is an exact steady solution (GasVerification); with them the gas next to
// each plate is slowed by its friction and the channel between them carries the difference.
TEST(GasBaffles, ThinPlateIsANoSlipWallOnBothSides) {
  const double U = 0.2;
  Scene s = test::boxScene(Vec3(0.1, 0.2, 0.005), Vec3(0.005, 0.005, 0.005), U * 0.1 * 0.005);
  s.apparatus.draft_plates = DraftPlatesSpec{0.06, 0.045, 0.035, 1e-5};
  s.gas.max_time_step = 2e-3;  // 150 steps (the CFL number stays below 0.2)
  gas::GasOptions o;
  o.slipFrontBack = o.slipSideWalls = o.boxBottomInlet = true;
  GasCase c(s, o);
  auto& g = *c.solver;
  // x from -0.05 m: the right plate (x 0.0225..0.02251) closes face column 15 (x = 0.025), the left
  // one face column 5; rows 7..18.
  ASSERT_TRUE(g.apertures().baffles.closes(0, 15, 12, 0));
  ASSERT_TRUE(g.apertures().baffles.closes(0, 5, 12, 0));
  while (g.time() < 0.3) g.step(1.0);
  const auto& ap = g.apertures();
  const auto uy = [&](int i, int j) { return g.faceVelocity(1)[face(ap, 1, i, j, 0)]; };
  const int j = 17;  // near the plates' upper edge: the flow has passed 5 cm of plate
  for (int i : {4, 5, 14, 15}) EXPECT_LT(uy(i, j), 0.97 * U) << "column " << i;  // beside a plate
  EXPECT_GT(uy(9, j), 1.01 * U);   // the channel centre carries more
  EXPECT_NEAR(uy(9, j), uy(10, j), 1e-6 * U);  // symmetric about x = 0 (to the pressure tolerance)
  EXPECT_NEAR(uy(14, j), uy(5, j), 1e-6 * U);
  // Measured: 0.153 U beside the plates, 1.06 U at the centre; without the no-slip mirror all four
  // columns read 1.000 U. Below the plates the stream is uniform up to their lower edges' disturbance.
  EXPECT_NEAR(uy(9, 2), U, 0.01 * U);
}

}  // namespace
}  // namespace rcfd
