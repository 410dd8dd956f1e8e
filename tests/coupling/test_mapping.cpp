// Particle volume mapping: exact conservation of the total volume, nothing in closed cells, alpha_P
// of the open volume, the over-packing redistribution and Eq. (3) smoothing conservative.

#include <gtest/gtest.h>

#include <algorithm>
#include <omp.h>
#include <random>

#include "CouplingTestSupport.hpp"
#include "cfddem/ApparatusWalls.hpp"

namespace rcfd {
namespace {

using coupling::FieldSmoother;
using coupling::KernelWeights;
using coupling::VolumeMapping;

struct SliceMapping {
  Scene scene = test::quickSlice();
  Apparatus apparatus{scene.apparatus};
  CartesianGrid grid = makeGrid(apparatus, scene.grid);
  gas::GasSolver gas{scene, apparatus, grid};
  DemSystem dem{DemMaterial::fromScene(scene), wallsFromApparatus(apparatus), DemSystem::settingsFromScene(scene)};
  VolumeMapping mapping{grid, gas.openFraction(), gas.activeCells()};
};

double totalParcelVolume(const DemParticles& p) {
  double v = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) v += coupling::parcelVolume(p, i);
  return v;
}

TEST(VolumeMapping, ConservesTheTotalParticleVolumeAndAvoidsClosedCells) {
  SliceMapping m;
  // Parcels everywhere in the chamber, many close to the V walls and the front/back walls (cut cells).
  test::scatterParcels(m.dem, m.apparatus, 3000, m.dem.material().particle_radius, 7, 0.3);
  std::vector<KernelWeights> w;
  std::vector<double> volume;
  m.mapping.weightsOf(m.dem.particles(), w);
  m.mapping.scatterVolume(m.dem.particles(), w, volume);
  double mapped = 0.0, inClosed = 0.0;
  for (std::size_t c = 0; c < volume.size(); ++c) {
    mapped += volume[c];
    if (!m.gas.activeCells()[c]) inClosed += volume[c];
  }
  const double total = totalParcelVolume(m.dem.particles());
  EXPECT_NEAR(mapped, total, 1e-13 * total);
  EXPECT_EQ(inClosed, 0.0);
  for (const auto& k : w) {
    double s = 0.0;
    for (int q = 0; q < k.count; ++q) {
      s += k.w[std::size_t(q)];
      EXPECT_GE(k.w[std::size_t(q)], 0.0);
    }
    EXPECT_NEAR(s, 1.0, 1e-15);
  }
  // alpha_P is of the open volume: summed back with V phi it gives the volume again.
  const std::vector<double> a = m.mapping.fractionOf(volume);
  double back = 0.0;
  for (std::size_t c = 0; c < a.size(); ++c) back += a[c] * m.mapping.openVolume(c);
  EXPECT_NEAR(back, total, 1e-13 * total);
}

TEST(VolumeMapping, TheParallelGatherIsTheSerialScatterToTheBit) {
  SliceMapping m;
  // More parcels than the parallel threshold, so the contributions are counted in chunks.
  test::scatterParcels(m.dem, m.apparatus, 6000, m.dem.material().particle_radius, 11, 0.3);
  ASSERT_GE(long(m.dem.particles().size()), coupling::kParallelParcels);
  std::vector<KernelWeights> w;
  std::vector<double> serial;
  m.mapping.weightsOf(m.dem.particles(), w);
  m.mapping.scatterVolume(m.dem.particles(), w, serial);
  const int threads = omp_get_max_threads();
  for (int t : {1, 2, 3}) {
    omp_set_num_threads(t);
    coupling::CellContributions c;
    std::vector<double> gathered;
    m.mapping.contributionsOf(w, c);
    m.mapping.gatherVolume(m.dem.particles(), c, gathered);
    ASSERT_EQ(gathered.size(), serial.size());
    for (std::size_t cell = 0; cell < serial.size(); ++cell) {
      EXPECT_EQ(gathered[cell], serial[cell]) << "cell " << cell << ", " << t << " threads";
      for (auto e = c.start[cell] + 1; e < c.start[cell + 1]; ++e)
        EXPECT_LT(c.parcel[std::size_t(e) - 1], c.parcel[std::size_t(e)]) << "cell " << cell;
    }
  }
  omp_set_num_threads(threads);
  // Inside another parallel region without nesting the team is one thread, whatever
  // omp_get_max_threads() says: every parcel is still counted.
  const int levels = omp_get_max_active_levels();
  omp_set_max_active_levels(1);
  std::vector<double> inner;
#pragma omp parallel num_threads(2)
  {
    coupling::CellContributions c;
    std::vector<double> gathered;
    m.mapping.contributionsOf(w, c);
    m.mapping.gatherVolume(m.dem.particles(), c, gathered);
    if (omp_get_thread_num() == 0) inner = gathered;
  }
  omp_set_max_active_levels(levels);
  EXPECT_EQ(inner, serial);
}

TEST(VolumeMapping, SmoothInsideACellAndExactForAParcelOnACentre) {
  SliceMapping m;
  const Eigen::Vector3d c = m.grid.cellCenter(25, 20, 1);
  const KernelWeights onCentre = m.mapping.weights(c);
  ASSERT_EQ(onCentre.count, 1);
  EXPECT_EQ(onCentre.cell[0], m.grid.flatIndex(25, 20, 1));
  // Moving a parcel by a small distance moves a small part of its volume (no jumps at cell faces).
  const Eigen::Vector3d h = m.grid.spacing;
  const KernelWeights a = m.mapping.weights(c + Eigen::Vector3d(0.49 * h.x(), 0, 0));
  const KernelWeights b = m.mapping.weights(c + Eigen::Vector3d(0.51 * h.x(), 0, 0));
  ASSERT_EQ(a.count, 2);
  ASSERT_EQ(b.count, 2);
  EXPECT_NEAR(a.w[0], 0.51, 1e-12);
  EXPECT_NEAR(b.w[0], 0.49, 1e-12);
}

TEST(VolumeMapping, TheVelocitySpreadSplitsTheMeanIntoItsUpAndDownParts) {
  SliceMapping m;
  test::scatterParcels(m.dem, m.apparatus, 3000, m.dem.material().particle_radius, 11, 0.3);
  DemParticles& p = m.dem.particles();
  for (std::size_t i = 0; i < p.size(); ++i) {  // up at 2 m/s or down at 0.5 m/s, with a lateral part
    p.v[i] = Eigen::Vector3d(0.1 * std::sin(double(i)), i % 3 == 0 ? 2.0 : -0.5, 0.0);
  }
  std::vector<KernelWeights> w;
  m.mapping.weightsOf(p, w);
  const auto spread = m.mapping.velocitySpread(p, w);
  const auto mean = m.mapping.meanVelocity(p, w);
  std::size_t mixed = 0;
  for (std::size_t c = 0; c < mean.size(); ++c) {
    EXPECT_EQ(spread.mean[c], mean[c]);
    const double f = spread.upFraction[c];
    ASSERT_GE(f, 0.0);
    ASSERT_LE(f, 1.0);
    const Eigen::Vector3d recombined = f * spread.up[c] + (1.0 - f) * spread.down[c];
    EXPECT_NEAR((recombined - mean[c]).norm(), 0.0, 1e-12) << c;
    if (f > 0.0) {
      EXPECT_NEAR(spread.up[c].y(), 2.0, 1e-12);
    }
    if (f < 1.0 && mean[c] != Eigen::Vector3d::Zero()) {
      EXPECT_NEAR(spread.down[c].y(), -0.5, 1e-12);
    }
    // Two velocities 2.5 m/s apart: no parcel is further than that from the mean at its position.
    EXPECT_GE(spread.variance[c].y(), 0.0);
    EXPECT_LE(spread.variance[c].y(), 6.25 * (1 + 1e-12)) << c;
    mixed += f > 0.0 && f < 1.0;
  }
  EXPECT_GT(mixed, 100u);
}

TEST(VolumeMapping, TheVelocitySpreadIsAboutTheMeanAtEachParcelNotTheShearAcrossTheKernel) {
  // u_y = G x + s xi: a shear the interpolated mean resolves, and a random part it cannot. Tracers
  // already move with the interpolated mean, so the variance should be s^2, not s^2 plus the shear's
  // G^2 h^2 / 6 across the trilinear kernel (0.018 m2/s2 here, 45 % of s^2).
  SliceMapping m;
  test::scatterParcels(m.dem, m.apparatus, 100000, m.dem.material().particle_radius, 5, 0.3);
  DemParticles& p = m.dem.particles();
  constexpr double kShear = 50.0, kSpread = 0.2;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> xi(0.0, 1.0);
  for (std::size_t i = 0; i < p.size(); ++i) p.v[i] = Eigen::Vector3d(0.0, kShear * p.x[i].x() + kSpread * xi(rng), 0.0);
  std::vector<KernelWeights> w;
  m.mapping.weightsOf(p, w);
  const auto spread = m.mapping.velocitySpread(p, w);
  // Cells whose neighbours along x and y are all fully open: the interpolation is exact for a linear
  // field there (closed cells only along z renormalise the z weights).
  double sum = 0.0;
  int cells = 0;
  for (int k = 0; k < m.grid.shape[2]; ++k)
    for (int j = 1; j + 1 < m.grid.shape[1]; ++j)
      for (int i = 1; i + 1 < m.grid.shape[0]; ++i) {
        bool open = m.grid.cellCenter(i, j, k).y() < 0.29;
        for (int dj = -1; dj <= 1; ++dj)
          for (int di = -1; di <= 1; ++di) {
            const auto n = std::size_t(m.grid.flatIndex(i + di, j + dj, k));
            open = open && m.mapping.usable()[n] && m.mapping.openFraction()[n] == 1.0;
          }
        if (!open) continue;
        sum += spread.variance[std::size_t(m.grid.flatIndex(i, j, k))].y();
        ++cells;
      }
  ASSERT_GT(cells, 100);
  EXPECT_NEAR(sum / cells, kSpread * kSpread, 0.08 * kSpread * kSpread);
}

TEST(VolumeMapping, OverPackedCellsGiveTheirExcessToNeighboursConservatively) {
  SliceMapping m;
  std::vector<double> volume(std::size_t(m.grid.cellCount()), 0.0);
  // A whole column of cells next to the V wall filled to alpha_P = 0.95 of its open volume, and its
  // neighbours at 0.6: the excess has to travel more than one cell.
  double total = 0.0;
  for (std::size_t c = 0; c < volume.size(); ++c) {
    if (!m.mapping.usable()[c]) continue;
    const auto ijk = m.grid.cellIjk(std::int64_t(c));
    const double y = m.grid.cellCenter(ijk[0], ijk[1], ijk[2]).y();
    if (y > 0.05) continue;
    volume[c] = (m.mapping.openFraction()[c] < 1.0 ? 0.95 : 0.6) * m.mapping.openVolume(c);
    total += volume[c];
  }
  const long gave = m.mapping.redistributeExcess(volume);
  EXPECT_GT(gave, 10);
  double after = 0.0, maxA = 0.0;
  const auto a = m.mapping.fractionOf(volume);
  for (std::size_t c = 0; c < volume.size(); ++c) after += volume[c], maxA = std::max(maxA, a[c]);
  EXPECT_NEAR(after, total, 1e-13 * total);
  EXPECT_LE(maxA, coupling::kMaxParticleFraction * (1 + 1e-8));
}

TEST(FieldSmoother, Equation3IsConservativeAndBounded) {
  SliceMapping m;
  test::scatterParcels(m.dem, m.apparatus, 2000, m.dem.material().particle_radius, 11, 0.12);
  std::vector<KernelWeights> w;
  std::vector<double> volume;
  m.mapping.weightsOf(m.dem.particles(), w);
  m.mapping.scatterVolume(m.dem.particles(), w, volume);
  std::vector<double> a = m.mapping.fractionOf(volume);
  const double maxBefore = *std::max_element(a.begin(), a.end());
  FieldSmoother s(m.mapping, m.gas.faceKinds(0), m.gas.faceKinds(1), m.gas.faceKinds(2), m.scene.gas.smoothing_length);
  EXPECT_GT(s.subSteps(), 1);
  s.smooth(a);
  double total = 0.0, maxAfter = 0.0, minAfter = 1.0;
  for (std::size_t c = 0; c < a.size(); ++c) {
    total += a[c] * m.mapping.openVolume(c);
    maxAfter = std::max(maxAfter, a[c]);
    if (m.mapping.usable()[c]) minAfter = std::min(minAfter, a[c]);
  }
  const double v = totalParcelVolume(m.dem.particles());
  EXPECT_NEAR(total, v, 1e-13 * v);
  EXPECT_LT(maxAfter, maxBefore);  // peaks come down
  EXPECT_GE(minAfter, 0.0);        // no negative fractions
}

}  // namespace
}  // namespace rcfd
