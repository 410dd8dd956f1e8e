// thinWallBaffles(): a plate thinner than a cell, inside one cell column, closes the face nearest to
// its mid-plane over its extent; plates resolved by the grid and apparatus without plates give none.

#include <gtest/gtest.h>

#include <cmath>

#include "GeometryFixtures.hpp"
#include "geometry/ThinWalls.hpp"

namespace rcfd {
namespace {

/// The quick slice: ProCell section 0.02 m deep, 5 mm cells (50 x 120 x 4), x from -0.125 m.
CartesianGrid sliceGrid(const Apparatus& app, double cell) {
  GridSpec spec;
  spec.cell_size = Vec3(cell, cell, cell);
  return makeGrid(app, spec);
}

ApparatusSpec slice(bool plates) {
  ApparatusSpec a = test::procellSpec(plates);
  a.depth = 0.02;
  return a;
}

TEST(ThinWalls, PlateInsideACellColumnClosesItsNearestFace) {
  const Apparatus app(slice(true));
  const CartesianGrid g = sliceGrid(app, 0.005);
  ASSERT_EQ(g.shape, (std::array<int, 3>{50, 120, 4}));
  const BaffleFaces b = thinWallBaffles(app, g);
  ASSERT_FALSE(b.empty());
  // Right plate x in [0.0225, 0.0245] lies in the column [0.020, 0.025]: its mid-plane 0.0235 is
  // 1.5 mm from the face x = 0.025 (index 30) and 3.5 mm from x = 0.020 (index 29). The left plate
  // mirrors it onto x = -0.025 (index 20). y from 0.035 to 0.095: rows 7..18, whole faces.
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 120; ++j) {
      const bool along = j >= 7 && j <= 18;
      for (int i = 0; i <= 50; ++i) {
        const bool baffle = along && (i == 30 || i == 20);
        ASSERT_EQ(b.covered[0][b.index(0, i, j, k)], baffle ? 1.0 : 0.0) << i << " " << j << " " << k;
        ASSERT_EQ(b.closes(0, i, j, k), baffle);
      }
    }
  // The plates are 12 cells tall: the grid's y-faces inside them are cut by FaceApertures already.
  EXPECT_TRUE(b.covered[1].empty());
  EXPECT_FALSE(b.closes(1, 30, 10, 0));
}

TEST(ThinWalls, APlateSeparatesTheCellsOnItsTwoSidesAndNoneBesideIt) {
  // 5 mm cells: the right plate lies in column i = 29 (x 0.020-0.025), snapped to the face x = 0.025.
  const Apparatus app(slice(true));
  const CartesianGrid g = sliceGrid(app, 0.005);
  const BaffleFaces b = thinWallBaffles(app, g);
  const std::array<int, 3> column{29, 10, 1}, annulus{30, 10, 1}, tube{28, 10, 1};
  EXPECT_TRUE(plateSeparates(app, g, b, column, 0, +1));  // across the baffle
  EXPECT_TRUE(plateSeparates(app, g, b, annulus, 0, -1));
  EXPECT_FALSE(plateSeparates(app, g, b, column, 0, -1));  // the column's other face: open
  EXPECT_FALSE(plateSeparates(app, g, b, tube, 0, +1));
  EXPECT_FALSE(plateSeparates(app, g, b, column, 1, +1));  // along the plate
  EXPECT_FALSE(plateSeparates(app, g, b, std::array<int, 3>{29, 30, 1}, 0, +1));  // above its top
  EXPECT_FALSE(plateSeparates(app, g, b, column, 2, +1));
  // On 1 mm cells the plate (x 0.0225-0.0245) contains the faces x = 0.023 and 0.024 and has no
  // baffle: those faces separate, the ones at its surfaces (0.0225 lies inside a cell) do not.
  const CartesianGrid fine = sliceGrid(app, 0.001);
  const BaffleFaces none = thinWallBaffles(app, fine);
  const int i = int(std::lround((0.023 - fine.origin.x()) / fine.spacing.x()));  // face index of x = 0.023
  EXPECT_TRUE(plateSeparates(app, fine, none, std::array<int, 3>{i - 1, 60, 1}, 0, +1));
  EXPECT_TRUE(plateSeparates(app, fine, none, std::array<int, 3>{i, 60, 1}, 0, +1));
  EXPECT_FALSE(plateSeparates(app, fine, none, std::array<int, 3>{i + 2, 60, 1}, 0, +1));
  EXPECT_FALSE(plateSeparates(app, fine, none, std::array<int, 3>{i - 3, 60, 1}, 0, +1));
}

TEST(ThinWalls, AFaceIndexPastTheDomainsEdgeIsNoBaffle) {
  // The gas solver's stencils ask for faces one and two cells beyond the domain's edge (the outer
  // walls are its ghost cells): such an index is no baffle and is never read from the face array.
  const Apparatus app(slice(true));
  const BaffleFaces b = thinWallBaffles(app, sliceGrid(app, 0.005));
  ASSERT_TRUE(b.closes(0, 30, 10, 0));
  EXPECT_FALSE(b.closes(0, 30, 10, -1));
  EXPECT_FALSE(b.closes(0, 30, 10, 4));
  EXPECT_FALSE(b.closes(0, -1, 10, 0));
  EXPECT_FALSE(b.closes(0, 51, 10, 0));
  EXPECT_FALSE(b.closes(1, 50, 10, 0));
  EXPECT_FALSE(b.closes(1, 10, 121, 0));
  EXPECT_FALSE(b.closes(2, 10, 10, 0));
}

TEST(ThinWalls, PartlyCoveredFaceAtAPlateTipIsNotClosed) {
  ApparatusSpec spec = slice(true);
  spec.draft_plates->elevation = 0.037;  // lower edge 3 mm into the row [0.035, 0.040]
  spec.draft_plates->height = 0.0605;    // upper edge at 0.0975, half-way up the row [0.095, 0.100]
  const Apparatus app(spec);
  const CartesianGrid g = sliceGrid(app, 0.005);
  const BaffleFaces b = thinWallBaffles(app, g);
  EXPECT_NEAR(b.covered[0][b.index(0, 30, 7, 2)], 0.6, 1e-12);
  EXPECT_FALSE(b.closes(0, 30, 7, 2));
  EXPECT_EQ(b.covered[0][b.index(0, 30, 8, 2)], 1.0);
  EXPECT_NEAR(b.covered[0][b.index(0, 30, 19, 2)], 0.5, 1e-12);
  EXPECT_EQ(b.covered[0][b.index(0, 30, 20, 2)], 0.0);
  EXPECT_EQ(b.covered[0][b.index(0, 30, 6, 2)], 0.0);
}

TEST(ThinWalls, PlateInTheLowerHalfOfItsColumnClosesTheLowerFace) {
  ApparatusSpec spec = slice(true);
  spec.draft_plates->gap = 0.042;  // right plate x in [0.021, 0.023]: mid-plane 2 mm above x = 0.020
  const Apparatus app(spec);
  const BaffleFaces b = thinWallBaffles(app, sliceGrid(app, 0.005));
  EXPECT_TRUE(b.closes(0, 29, 10, 0));   // x = 0.020
  EXPECT_FALSE(b.closes(0, 30, 10, 0));  // x = 0.025
  EXPECT_TRUE(b.closes(0, 21, 10, 0));   // the left plate mirrors it onto x = -0.020
}

TEST(ThinWalls, APointBetweenAPlateAndItsBaffleFaceBelongsToTheCellAcrossTheFace) {
  // 5 mm cells: the right plate (x 0.0225-0.0245) is snapped to x = 0.025, leaving the strip
  // 0.0245-0.025 of column 29 beyond the plate: the annulus's side. The left plate mirrors it.
  const Apparatus app(slice(true));
  const CartesianGrid g = sliceGrid(app, 0.005);
  const BaffleFaces b = thinWallBaffles(app, g);
  ASSERT_EQ(b.strips.size(), 2u);
  using V = Eigen::Vector3d;
  EXPECT_EQ(b.homeCell(g, V(0.0248, 0.06, 0.01)), (std::array<int, 3>{30, 12, 2}));   // strip: annulus
  EXPECT_EQ(b.homeCell(g, V(0.0215, 0.06, 0.01)), (std::array<int, 3>{29, 12, 2}));   // tube side: own
  EXPECT_EQ(b.homeCell(g, V(-0.0248, 0.06, 0.01)), (std::array<int, 3>{19, 12, 2}));  // left strip
  EXPECT_EQ(b.homeCell(g, V(0.0248, 0.0975, 0.01)), (std::array<int, 3>{29, 19, 2}));  // above the plate
  // The per-cell plate faces mark the baffles from the lower cell.
  const auto faces = plateFacesAbove(app, g);
  EXPECT_EQ(faces[std::size_t(g.flatIndex(29, 12, 2))], kPlateAboveX);
  EXPECT_EQ(faces[std::size_t(g.flatIndex(30, 12, 2))], 0);
  EXPECT_EQ(faces[std::size_t(g.flatIndex(19, 12, 2))], kPlateAboveX);  // the face x = -0.025 (index 20)
  // A plate containing faces closes them itself (1 mm cells): they are plate faces too.
  const CartesianGrid mm = sliceGrid(app, 0.001);
  const auto resolved = plateFacesAbove(app, mm);
  const int face = int(std::lround((0.023 - mm.origin.x()) / mm.spacing.x()));
  EXPECT_EQ(resolved[std::size_t(mm.flatIndex(face - 1, 60, 1))], kPlateAboveX);
  EXPECT_EQ(resolved[std::size_t(mm.flatIndex(face + 2, 60, 1))], 0);
  // Snapped to the lower face (gap 0.042: plate 0.021-0.023, face 0.020), the strip is the tube's.
  ApparatusSpec lower = slice(true);
  lower.draft_plates->gap = 0.042;
  const Apparatus low(lower);
  const BaffleFaces lb = thinWallBaffles(low, g);
  EXPECT_EQ(lb.homeCell(g, V(0.0205, 0.06, 0.01)), (std::array<int, 3>{28, 12, 2}));
  EXPECT_EQ(lb.homeCell(g, V(0.0235, 0.06, 0.01)), (std::array<int, 3>{29, 12, 2}));
  // Plates the grid resolves have no strips.
  EXPECT_TRUE(thinWallBaffles(app, sliceGrid(app, 0.0005)).strips.empty());
}

TEST(ThinWalls, ResolvedPlatesAndApparatusWithoutPlatesHaveNoBaffles) {
  // 0.5 mm cells: faces lie inside the plates (they are closed by the cut cells and face apertures).
  const Apparatus plates(slice(true));
  EXPECT_TRUE(thinWallBaffles(plates, sliceGrid(plates, 0.0005)).empty());
  const Apparatus none(slice(false));
  EXPECT_TRUE(thinWallBaffles(none, sliceGrid(none, 0.005)).empty());
  const Apparatus box(test::boxSpec(0.1, 0.2, 0.02, true));
  EXPECT_TRUE(thinWallBaffles(box, sliceGrid(box, 0.005)).empty());
}

}  // namespace
}  // namespace rcfd
