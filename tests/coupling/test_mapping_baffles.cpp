// Draft plates thinner than a cell (the quick slice: 2 mm plates in 5 mm cell columns) in the coupling:
// the cloud-in-cell mapping puts no particle volume behind a plate and conserves it, the over-packing
// redistribution and the Eq. (3) smoothing exchange nothing across a plate and conserve.

#include <gtest/gtest.h>

#include <algorithm>

#include "CouplingTestSupport.hpp"
#include "cfddem/ApparatusWalls.hpp"

namespace rcfd {
namespace {

using coupling::FieldSmoother;
using coupling::KernelWeights;
using coupling::VolumeMapping;

// The right plate (x 0.0225..0.0245, y 0.035..0.095) closes the face x = 0.025 (face column 30, between
// cell columns 29 and 30) over rows 7..18; the left one mirrors it at x = -0.025 (face column 20).
constexpr double kRightFace = 0.025;
constexpr int kRightCol = 30, kLeftCol = 20, kFirstRow = 7, kLastRow = 18;

Scene plateSlice() {
  Scene s = test::quickSlice();
  s.apparatus.draft_plates = DraftPlatesSpec{};
  return s;
}

struct PlateMapping {
  Scene scene = plateSlice();
  Apparatus apparatus{scene.apparatus};
  CartesianGrid grid = makeGrid(apparatus, scene.grid);
  gas::GasSolver gas{scene, apparatus, grid};
  DemSystem dem{DemMaterial::fromScene(scene), wallsFromApparatus(apparatus), DemSystem::settingsFromScene(scene)};
  VolumeMapping mapping{grid, gas.openFraction(), gas.activeCells(), gas.apertures().baffles};
  /// The same without the baffles: what the mapping did before plates closed faces.
  VolumeMapping transparent{grid, gas.openFraction(), gas.activeCells()};
};

/// Which side of the plates a point or cell centre is on: -1 left of the left plate, 0 between, 1 right.
int side(double x) { return x > kRightFace ? 1 : (x < -kRightFace ? -1 : 0); }
bool alongPlates(double y) { return y > 0.035 && y < 0.095; }

/// Number of (parcel, cell) weights that put volume of a parcel beside the plates into a cell beside
/// the plates on their other side.
long crossings(const PlateMapping& m, const VolumeMapping& mapping) {
  std::vector<KernelWeights> w;
  mapping.weightsOf(m.dem.particles(), w);
  long n = 0;
  const auto& x = m.dem.particles().x;
  for (std::size_t i = 0; i < w.size(); ++i) {
    if (!alongPlates(x[i].y())) continue;
    for (int q = 0; q < w[i].count; ++q) {
      const auto ijk = m.grid.cellIjk(w[i].cell[std::size_t(q)]);
      const Eigen::Vector3d c = m.grid.cellCenter(ijk[0], ijk[1], ijk[2]);
      if (ijk[1] >= kFirstRow && ijk[1] <= kLastRow && side(c.x()) != side(x[i].x()) && w[i].w[std::size_t(q)] > 0) ++n;
    }
  }
  return n;
}

TEST(MappingBaffles, NoParticleVolumeBehindAPlateAndTheTotalConserved) {
  PlateMapping m;
  // Parcels all over the lower chamber, many beside the plates (at least one radius from every wall).
  test::scatterParcels(m.dem, m.apparatus, 4000, m.dem.material().particle_radius, 5, 0.12);
  EXPECT_EQ(crossings(m, m.mapping), 0);
  EXPECT_GT(crossings(m, m.transparent), 50);  // the cell kernel alone spreads them through the plates
  std::vector<KernelWeights> w;
  std::vector<double> volume;
  m.mapping.weightsOf(m.dem.particles(), w);
  m.mapping.scatterVolume(m.dem.particles(), w, volume);
  double mapped = 0.0, total = 0.0;
  for (double v : volume) mapped += v;
  for (std::size_t i = 0; i < m.dem.particles().size(); ++i) total += coupling::parcelVolume(m.dem.particles(), i);
  EXPECT_NEAR(mapped, total, 1e-13 * total);
  for (const auto& k : w) {
    double s = 0.0;
    for (int q = 0; q < k.count; ++q) s += k.w[std::size_t(q)];
    ASSERT_NEAR(s, 1.0, 1e-15);
  }
}

TEST(MappingBaffles, ParcelOutsideAPlateKeepsItsVolumeOnItsSide) {
  PlateMapping m;
  const double r = m.dem.material().particle_radius;
  // Touching the right plate's outer face (x = 0.0245) at mid-height: the trilinear kernel reaches the
  // centre of column 29 (x = 0.0225), behind the plate.
  const Eigen::Vector3d outside(0.0245 + r, 0.065, 0.01);
  const KernelWeights open = m.transparent.weights(outside);
  const KernelWeights cut = m.mapping.weights(outside);
  bool reachedBehind = false;
  for (int q = 0; q < open.count; ++q) reachedBehind |= m.grid.cellIjk(open.cell[std::size_t(q)])[0] < kRightCol;
  EXPECT_TRUE(reachedBehind);
  double sum = 0.0;
  for (int q = 0; q < cut.count; ++q) {
    EXPECT_GE(m.grid.cellIjk(cut.cell[std::size_t(q)])[0], kRightCol);
    sum += cut.w[std::size_t(q)];
  }
  EXPECT_NEAR(sum, 1.0, 1e-15);
  // Above the plate's upper edge the kernel is whole again (nothing to cross).
  const Eigen::Vector3d above(0.0245 + r, 0.1 + 0.0001, 0.01);
  EXPECT_EQ(m.mapping.weights(above).count, m.transparent.weights(above).count);
}

TEST(MappingBaffles, ParcelBetweenAPlateAndItsBaffleFaceMapsToThePlatesSideItIsOn) {
  // Column 29 (x 0.020-0.025) holds the right plate (0.0225-0.0245), snapped to x = 0.025: a parcel
  // centre in the strip 0.0245-0.025 is on the annulus's side of the plate though its cell is on the
  // tube's side of the baffle (on the quick example's 6.6 mm cells the annulus's parcels resting
  // against the plate have their centres there). Its volume goes to the annulus's cells, none to the tube's.
  PlateMapping m;
  const Eigen::Vector3d strip(0.0248, 0.065, 0.01);
  ASSERT_EQ(m.grid.cellOf(strip)[0], kRightCol - 1);
  const KernelWeights w = m.mapping.weights(strip);
  double sum = 0.0;
  for (int q = 0; q < w.count; ++q) {
    EXPECT_GE(m.grid.cellIjk(w.cell[std::size_t(q)])[0], kRightCol);
    sum += w.w[std::size_t(q)];
  }
  EXPECT_NEAR(sum, 1.0, 1e-15);
  // On the tube's side of the plate, the same distance from it, the volume stays in the tube.
  const KernelWeights tube = m.mapping.weights(Eigen::Vector3d(0.0222, 0.065, 0.01));
  for (int q = 0; q < tube.count; ++q) EXPECT_LT(m.grid.cellIjk(tube.cell[std::size_t(q)])[0], kRightCol);
}

TEST(MappingBaffles, ExcessVolumeDoesNotCrossAPlate) {
  PlateMapping m;
  std::vector<double> volume(std::size_t(m.grid.cellCount()), 0.0);
  // An over-packed cell of the plate column (inside the channel, phi 0.6) at mid-height.
  const std::size_t c = std::size_t(m.grid.flatIndex(kRightCol - 1, 12, 1));
  const std::size_t behind = std::size_t(m.grid.flatIndex(kRightCol, 12, 1));
  volume[c] = 0.95 * m.mapping.openVolume(c);
  const double total = volume[c];
  EXPECT_EQ(m.mapping.redistributeExcess(volume), 1);
  EXPECT_EQ(volume[behind], 0.0);
  EXPECT_GT(volume[std::size_t(m.grid.flatIndex(kRightCol - 2, 12, 1))], 0.0);
  double after = 0.0;
  for (double v : volume) after += v;
  EXPECT_NEAR(after, total, 1e-13 * total);
  std::vector<double> open(volume.size(), 0.0);
  open[c] = total;
  m.transparent.redistributeExcess(open);
  EXPECT_GT(open[behind], 0.0);  // without the baffle it would
}

TEST(MappingBaffles, SmoothingConservesAndDoesNotCrossAPlate) {
  PlateMapping m;
  // gamma = 1 in the channel between the plates along their height, 0 elsewhere.
  std::vector<double> a(std::size_t(m.grid.cellCount()), 0.0);
  for (int k = 0; k < m.grid.shape[2]; ++k)
    for (int j = kFirstRow; j <= kLastRow; ++j)
      for (int i = kLeftCol; i < kRightCol; ++i) a[std::size_t(m.grid.flatIndex(i, j, k))] = 1.0;
  auto integral = [&](const std::vector<double>& g) {
    double s = 0.0;
    for (std::size_t c = 0; c < g.size(); ++c) s += g[c] * m.mapping.openVolume(c);
    return s;
  };
  const double before = integral(a);
  const FieldSmoother s(m.mapping, m.gas.faceKinds(0), m.gas.faceKinds(1), m.gas.faceKinds(2),
                        m.scene.gas.smoothing_length);
  std::vector<double> smoothed = a;
  s.smooth(smoothed);
  EXPECT_NEAR(integral(smoothed), before, 1e-13 * before);
  // Behind the plates at mid-height (row 12): nothing. The way round a plate's edge from the channel to
  // that cell is 8 face steps; each explicit sub-step reaches one step further (7 sub-steps here).
  ASSERT_LT(s.subSteps(), 8);
  for (int k = 0; k < m.grid.shape[2]; ++k) {
    EXPECT_EQ(smoothed[std::size_t(m.grid.flatIndex(kRightCol, 12, k))], 0.0);
    EXPECT_EQ(smoothed[std::size_t(m.grid.flatIndex(kLeftCol - 1, 12, k))], 0.0);
  }
  // Inside, the field spreads along the channel ends (it is smoothed at all).
  EXPECT_GT(smoothed[std::size_t(m.grid.flatIndex(25, kLastRow + 1, 1))], 0.0);
  // With the baffle faces open the same smoothing puts gamma behind the plates.
  std::vector<char> openX = m.gas.faceKinds(0);
  const auto& sh = m.gas.apertures().shape[0];
  for (int k = 0; k < sh[2]; ++k)
    for (int j = kFirstRow; j <= kLastRow; ++j)
      for (int i : {kLeftCol, kRightCol}) openX[(std::size_t(k) * sh[1] + j) * sh[0] + i] = gas::GasSolver::Interior;
  const FieldSmoother leaky(m.mapping, openX, m.gas.faceKinds(1), m.gas.faceKinds(2), m.scene.gas.smoothing_length);
  std::vector<double> crossed = a;
  leaky.smooth(crossed);
  EXPECT_GT(crossed[std::size_t(m.grid.flatIndex(kRightCol, 12, 1))], 0.01);
}

}  // namespace
}  // namespace rcfd
