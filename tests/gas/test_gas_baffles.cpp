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

}  // namespace
}  // namespace rcfd
