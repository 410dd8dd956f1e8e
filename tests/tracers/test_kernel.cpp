// The motion kernel's fast (vectorised block) path against its scalar path, and the pieces it is built
// from: counter-based unit vectors with the polynomial sincos, and the trilinear locator.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <iostream>
#include <random>
#include <string>

#include "core/Isa.hpp"
#include "tracers/BlockLanes.hpp"
#include "tracers/BlockSampling.hpp"
#include "tracers/CellIndex.hpp"
#include "tracers/FluctuationModel.hpp"
#include "tracers/FrameSampler.hpp"
#include "tracers/SingleSphereDrag.hpp"
#include "tracers/UnitVectors.hpp"
#include "TracerTestSupport.hpp"
#include "../ScopedVariable.hpp"

using namespace rcfd;
using namespace rcfd::test;

TEST(Kernel, UnitVectorsAreTheirDirectionBitsInFloatAndUniform) {
  const CounterRngPrefix prefix(42, RngPurpose::Fluctuation, 1234);
  double worst = 0.0, worstNorm = 0.0;
  for (std::uint64_t i = 0; i < 200000; ++i) {
    // The same 24-bit integers evaluated in double with libm.
    std::uint32_t zBits, azimuthBits;
    counterDirectionBits(prefix, i, zBits, azimuthBits);
    ASSERT_LT(zBits, 1u << 24);
    ASSERT_LT(azimuthBits, 1u << 24);
    const double z = 2.0 * (double(zBits) * 0x1.0p-24) - 1.0;
    const double phi = 2.0 * std::numbers::pi * (double(azimuthBits) * 0x1.0p-24);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Eigen::Vector3d expected(r * std::cos(phi), r * std::sin(phi), z);
    double x, y, zf;
    counterUnitVector(prefix, i, x, y, zf);
    ASSERT_EQ(zf, z) << i;  // exact in float
    worst = std::max(worst, (Eigen::Vector3d(x, y, zf) - expected).cwiseAbs().maxCoeff());
    worstNorm = std::max(worstNorm, std::abs(Eigen::Vector3d(x, y, zf).norm() - 1.0));
  }
  // Float arithmetic: a few ulp of float (6e-8), also near the poles where 1 - z^2 loses digits.
  EXPECT_LT(worst, 1e-6);
  EXPECT_LT(worstNorm, 5e-7);
  // Uniform on the sphere, over the tracers of one step and over the steps of one tracer: E[n] = 0,
  // E[n n^T] = I / 3 (standard errors ~0.0013 and ~0.0007 here), and one tracer's directions in
  // successive steps uncorrelated, E[n_s . n_s+1] = 0 (standard error ~0.0013).
  const int draws = 200000;
  for (const bool overSteps : {false, true}) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero(), previous = Eigen::Vector3d::Zero();
    Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
    double lagOne = 0.0;
    for (int i = 0; i < draws; ++i) {
      double x, y, z;
      if (overSteps) {
        counterUnitVector(CounterRngPrefix(42, RngPurpose::Fluctuation, std::uint64_t(i)), 7, x, y, z);
      } else {
        counterUnitVector(prefix, std::uint64_t(i), x, y, z);
      }
      const Eigen::Vector3d n(x, y, z);
      mean += n / draws;
      second += n * n.transpose() / draws;
      lagOne += n.dot(previous) / draws;
      previous = n;
    }
    EXPECT_LT(mean.cwiseAbs().maxCoeff(), 0.006) << overSteps;
    EXPECT_LT((second - Eigen::Matrix3d::Identity() / 3.0).cwiseAbs().maxCoeff(), 0.004) << overSteps;
    EXPECT_LT(std::abs(lagOne), 0.006) << overSteps;
  }
  // Different seeds give different directions to the same tracer in the same step.
  int same = 0;
  for (std::uint64_t i = 0; i < 1000; ++i) {
    std::uint32_t a, b, c, d;
    counterDirectionBits(CounterRngPrefix(1, RngPurpose::Fluctuation, 5), i, a, b);
    counterDirectionBits(CounterRngPrefix(2, RngPurpose::Fluctuation, 5), i, c, d);
    same += a == c || b == d;
  }
  EXPECT_LE(same, 1);
  // Quadrant boundaries of the reduction, and the polynomials' accuracy over a fine sweep.
  for (float u : {0.0f, 0.125f, 0.25f, 0.375f, 0.5f, 0.625f, 0.75f, 0.875f, 1.0f - 0x1.0p-24f}) {
    float s, c;
    sinCosTwoPiFloat(u, s, c);
    EXPECT_NEAR(s, std::sin(2 * std::numbers::pi * double(u)), 2e-7) << u;
    EXPECT_NEAR(c, std::cos(2 * std::numbers::pi * double(u)), 2e-7) << u;
  }
  double worstTrig = 0.0;
  for (int k = 0; k < (1 << 16); ++k) {
    const float u = float(k) * 0x1.0p-16f;
    float s, c;
    sinCosTwoPiFloat(u, s, c);
    worstTrig = std::max({worstTrig, std::abs(s - std::sin(2 * std::numbers::pi * double(u))),
                          std::abs(c - std::cos(2 * std::numbers::pi * double(u)))});
  }
  EXPECT_LT(worstTrig, 2e-7);
}

// The vectorised cell lookup of the kernel and of tracer_volume_fraction agrees with the grid's own
// (floor of the division) inside, and sends every point outside, however far and NaN too, to a cell
// of the grid: the nearest one, NaN to the first.
TEST(Kernel, CellIndexerFindsTheGridsCellAndTheNearestOneOutside) {
  CartesianGrid grid;
  grid.origin = {-0.1, 0.02, -0.3};
  grid.spacing = {0.01, 0.02, 0.005};
  grid.shape = {7, 5, 3};
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> inside(0.0, 1.0);
  std::vector<double> x, y, z;
  for (int k = 0; k < 200; ++k) {
    x.push_back(grid.origin.x() + inside(rng) * grid.shape[0] * grid.spacing.x());
    y.push_back(grid.origin.y() + inside(rng) * grid.shape[1] * grid.spacing.y());
    z.push_back(grid.origin.z() + inside(rng) * grid.shape[2] * grid.spacing.z());
  }
  const std::size_t inGrid = x.size();
  // Outside, with the cell expected: (i, j, k) of the nearest cell; NaN goes to the first layer.
  const double huge = 1e30, nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<std::pair<std::array<double, 3>, std::array<int, 3>>> outside = {
      {{-1.0, 0.05, -0.2925}, {0, 1, 1}},   {{1.0, 0.05, -0.2925}, {6, 1, 1}},
      {{-0.055, -huge, -0.2925}, {4, 0, 1}}, {{-0.055, huge, -0.2925}, {4, 4, 1}},
      {{-0.055, 0.05, huge}, {4, 1, 2}},     {{huge, huge, huge}, {6, 4, 2}},
      {{-huge, -huge, -huge}, {0, 0, 0}},    {{nan, 0.05, -0.2925}, {0, 1, 1}},
      {{-0.055, nan, nan}, {4, 0, 0}}};
  for (const auto& [p, ijk] : outside) x.push_back(p[0]), y.push_back(p[1]), z.push_back(p[2]);
  std::vector<std::int32_t> cells(x.size());
  CellIndexer(grid).cellsOf(int(x.size()), x.data(), y.data(), z.data(), cells.data());
  for (std::size_t k = 0; k < inGrid; ++k) {
    EXPECT_EQ(cells[k], grid.flatIndexOf({x[k], y[k], z[k]})) << "point " << k;
  }
  for (std::size_t k = 0; k < outside.size(); ++k) {
    const auto& ijk = outside[k].second;
    EXPECT_EQ(cells[inGrid + k], grid.flatIndex(ijk[0], ijk[1], ijk[2])) << "outside point " << k;
  }
}

TEST(Kernel, SamplerMatchesWeightedTrilinearIncludingASingleLayerAndOutside) {
  CartesianGrid g;
  g.origin = Eigen::Vector3d(-0.1, 0.0, 0.02);
  g.spacing = Eigen::Vector3d(0.01, 0.02, 0.03);
  g.shape = {7, 5, 1};  // one layer in z: both z corners are the same cell
  FieldFrame f;
  f.alpha_p.assign(std::size_t(g.cellCount()), 0.0f);
  f.u_p.resize(3 * std::size_t(g.cellCount()));
  f.u_g.resize(3 * std::size_t(g.cellCount()));
  std::mt19937_64 gen(3);
  std::uniform_real_distribution<double> value(-2.0, 2.0);
  for (auto& v : f.u_p) v = float(value(gen));
  for (auto& v : f.u_g) v = float(value(gen));
  const FrameSampler sampler(g, &f);
  std::uniform_real_distribution<double> px(-0.12, -0.1 + 0.07 + 0.02), py(-0.01, 0.11), pz(0.0, 0.06);
  for (int n = 0; n < 2000; ++n) {
    const Eigen::Vector3d p(px(gen), py(gen), pz(gen));
    // Reference: clamped fractions, weighted sum of the 8 corners.
    int lo[3];
    double w[3];
    for (int d = 0; d < 3; ++d) {
      const double t = std::clamp((p[d] - g.origin[d]) / g.spacing[d] - 0.5, 0.0, double(g.shape[d] - 1));
      lo[d] = std::min(int(t), std::max(g.shape[d] - 2, 0));
      w[d] = t - lo[d];
    }
    Eigen::Vector3d expected = Eigen::Vector3d::Zero();
    for (int c = 0; c < 8; ++c) {
      const int i = std::min(lo[0] + (c & 1), g.shape[0] - 1);
      const int j = std::min(lo[1] + ((c >> 1) & 1), g.shape[1] - 1);
      const int k = std::min(lo[2] + (c >> 2), g.shape[2] - 1);
      const double weight = ((c & 1) ? w[0] : 1 - w[0]) * ((c & 2) ? w[1] : 1 - w[1]) * ((c & 4) ? w[2] : 1 - w[2]);
      const float* v = f.u_p.data() + 3 * g.flatIndex(i, j, k);
      expected += weight * Eigen::Vector3d(v[0], v[1], v[2]);
    }
    ASSERT_LT((sampler.velocity(p, false) - expected).cwiseAbs().maxCoeff(), 1e-12) << p.transpose();
  }
}

/// The block path's sampling (AVX2 loads of corner pairs where the grid has x-neighbours, the scalar
/// combination otherwise) gives interpolateCorners() bit for bit, and both stay within float rounding
/// of the double trilinear weights: on a grid with several layers and on one with a single x layer.
TEST(Kernel, BlockSamplingEqualsTheScalarCombinationBitForBit) {
  for (const std::array<int, 3> shape : {std::array<int, 3>{9, 6, 4}, std::array<int, 3>{1, 6, 4}}) {
    CartesianGrid g;
    g.origin = Eigen::Vector3d(-0.05, 0.0, 0.0);
    g.spacing = Eigen::Vector3d(0.01, 0.015, 0.02);
    g.shape = shape;
    const TrilinearLocator locator(g);
    std::mt19937_64 gen(11);
    std::uniform_real_distribution<double> value(-3.0, 3.0);
    std::vector<float> field(4 * std::size_t(g.cellCount()) + 8, 0.0f);  // 4 floats per cell, lane 3 zero
    for (std::int64_t c = 0; c < g.cellCount(); ++c) {
      for (int d = 0; d < 3; ++d) field[4 * std::size_t(c) + std::size_t(d)] = float(value(gen));
    }
    block::CornerOffsets corners;
    corners.set(locator.offsets32());
    EXPECT_EQ(corners.pairLoads, shape[0] > 1);
    std::uniform_real_distribution<double> px(-0.06, 0.05), py(-0.01, 0.1), pz(-0.01, 0.09);
    constexpr int n = block::kBlock;
    alignas(64) double x[n], y[n], z[n], ax[n], ay[n], az[n], ux[n], uy[n], uz[n];
    for (int round = 0; round < 50; ++round) {
      for (int k = 0; k < n; ++k) {
        x[k] = px(gen), y[k] = py(gen), z[k] = pz(gen);
        ax[k] = value(gen), ay[k] = value(gen), az[k] = value(gen);
      }
      block::BlockStencils s;
      block::locateBlock(locator.constants(), n, x, y, z, s);
      block::sampleBlock(field.data(), corners, s, n, ax, ay, az, ux, uy, uz);
      for (int k = 0; k < n; ++k) {
        const TrilinearStencil t = locator.locate(Eigen::Vector3d(x[k], y[k], z[k]));
        ASSERT_EQ(t.base, s.base[k]);
        float u[3];
        block::interpolateCorners(field.data() + 4 * t.base, corners.off, float(t.f[0]), float(t.f[1]),
                                  float(t.f[2]), u);
        ASSERT_EQ(ux[k], double(u[0]) + ax[k]);
        ASSERT_EQ(uy[k], double(u[1]) + ay[k]);
        ASSERT_EQ(uz[k], double(u[2]) + az[k]);
        double corner[8];
        for (int c = 0; c < 8; ++c) corner[c] = field[4 * std::size_t(t.base + locator.offset(c))];
        EXPECT_NEAR(u[0], trilinear(corner, t.f), 3e-6);  // float rounding of values up to 3
      }
    }
  }
}

namespace {
/// Swirling flow in a box with walls and fluctuation: most tracers take the vectorised block path in
/// one sub-step, the fast ones sub-steps in the block path, those near walls the exact wall test. Forcing
/// every tracer through the scalar path must give the same trajectories (up to the last bits of a fused
/// multiply-add). With `freeFlight`, the dilute stripes (alpha_P^rec < 0.02) put some lanes of most
/// blocks into free flight (drag toward u_G^rec, gravity, restitution at the walls).
/// With `plates`, the same flow runs through the ProCell prism with draft plates (V walls, plates), so
/// the vectorised wall test meets inclined walls and the plates' distance bound.
/// With `speed` above 1 the flow is that many times faster: at 3, most tracers take two or more
/// sub-steps, so most blocks take them in place (MotionKernel::advanceInPlace()) and the rest defer them.
void expectBlockPathMatchesScalarPath(bool freeFlight, bool plates = false, double speed = 1.0) {
  std::vector<std::string> effects = {"transport", "walls", "fluctuation", "tracer_volume_fraction"};
  if (freeFlight) effects.push_back("free_flight");
  Scene s = boxScene({0.2, 0.2, 0.2}, 0.01, 6000, 0.005, effects);
  if (plates) {
    s.apparatus = Scene{}.apparatus;  // ProCell
    s.apparatus.draft_plates = DraftPlatesSpec{0.06, 0.045, 0.035, 0.002};
    s.process.bed_mass = Scene{}.process.bed_mass;
  }
  s.rcfd.d0 = 5e-4;
  const CartesianGrid grid = gridOf(s);
  // A cellular flow tangent to the walls x = -0.1, 0.1 and y = 0, 0.2 and free of divergence (the box
  // spans x in [-w/2, w/2], y and z from 0), so tracers stay spread and only the fluctuation and the
  // corners of the cells bring them to the walls; 2.2 m/s peaks (1.1 cells per step) are sub-stepped.
  const double alphaMin = freeFlight ? -0.1 : 0.05;  // below 0.02 in stripes when free flight is on
  auto db = database(s, 6, s.rcfd.dt, [grid, alphaMin, speed](int n, double t, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      const auto p = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
      const double X = std::numbers::pi * (p.x() + 0.1) / 0.2, Y = std::numbers::pi * p.y() / 0.2;
      const double U = speed * 2.2 * (1.0 + 0.05 * std::sin(3 * t + n));
      const double alpha = alphaMin + 0.25 + 0.25 * std::sin(40 * p.x() + 3 * t);
      f.alpha_p[std::size_t(c)] = float(std::max(alpha, 0.0));
      f.u_p[3 * c] = float(U * std::sin(X) * std::cos(Y));
      f.u_p[3 * c + 1] = float(-U * std::cos(X) * std::sin(Y));
      f.u_p[3 * c + 2] = 0.0f;
      f.u_g[3 * c] = 0.5f * f.u_p[3 * c], f.u_g[3 * c + 1] = 0.5f * f.u_p[3 * c + 1], f.u_g[3 * c + 2] = 0.0f;
    }
  });
  const std::int64_t steps = 40;
  TracerSimulation block(s, db, sequentialPath(6, steps + 2), {5, steps, 0, true});
  TracerSimulation scalar(s, db, sequentialPath(6, steps + 2), {5, steps, 0, false});
  std::int64_t scalarPathTracers = 0, exactWallTests = 0, wallHits = 0, substeps = 0, freeFlying = 0;
  std::int64_t blocksInPlace = 0;
  for (std::int64_t k = 0; k < steps; ++k) {
    block.step();
    scalar.step();
    const MotionStatistics& b = block.motionStatistics();
    scalarPathTracers += b.scalarPath, exactWallTests += b.exactWallTests, wallHits += b.wallHits;
    substeps += b.substeps, freeFlying += b.freeFlight, blocksInPlace += b.blocksInPlace;
    EXPECT_EQ(b.scalarPath, 0);  // the block path moves everything, free flight included
    EXPECT_EQ(scalar.motionStatistics().scalarPath, std::int64_t(s.rcfd.tracers));
    EXPECT_EQ(scalar.motionStatistics().substeps, b.substeps);
  }
  // In the box 27% of the 8000 cells lie next to a wall: the vectorised wall tests clear nearly every
  // move there that hits nothing, so the exact test mostly sees moves that do reflect.
  EXPECT_LT(exactWallTests - wallHits, steps * s.rcfd.tracers / 50) << exactWallTests << " exact tests";
  EXPECT_GT(substeps, 0);  // all the ways a tracer can move were taken
  EXPECT_GT(exactWallTests, 0);
  EXPECT_GT(wallHits, 0);
  if (freeFlight) {
    EXPECT_GT(freeFlying, steps * s.rcfd.tracers / 100);
    EXPECT_LT(freeFlying, steps * s.rcfd.tracers / 2);
  }
  EXPECT_EQ(scalarPathTracers, 0);
  const std::int64_t blocks = steps * ((s.rcfd.tracers + 63) / 64);
  if (speed > 2.0) {
    EXPECT_GT(blocksInPlace, blocks / 2);
  } else {
    EXPECT_LT(blocksInPlace, blocks / 10);  // the slow flow defers its few sub-steps
  }
  double worst = 0.0;
  for (std::size_t i = 0; i < block.cloud().size(); ++i) {
    worst = std::max(worst, (block.cloud().position(i) - scalar.cloud().position(i)).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-9) << "metres, after 40 steps of up to 11 mm";
}
}  // namespace

TEST(Kernel, BlockPathMatchesScalarPath) { expectBlockPathMatchesScalarPath(false); }

TEST(Kernel, BlockPathMatchesScalarPathWithFreeFlightLanes) { expectBlockPathMatchesScalarPath(true); }

TEST(Kernel, BlockPathMatchesScalarPathWithSubstepsInPlace) { expectBlockPathMatchesScalarPath(false, false, 3.0); }

TEST(Kernel, BlockPathMatchesScalarPathWithSubstepsInPlaceAndFreeFlight) {
  expectBlockPathMatchesScalarPath(true, false, 3.0);
}

TEST(Kernel, BlockPathMatchesScalarPathInThePrismWithDraftPlates) { expectBlockPathMatchesScalarPath(false, true); }

TEST(Kernel, VectorisablePowAndDragFactorMatchStdPow) {
  // Re from 1e-13 to 1e3 on a log scale, as free flight meets it, and the ends of the regimes.
  double worst = 0.0;
  for (int i = 0; i <= 200000; ++i) {
    const double re = std::pow(10.0, -13.0 + 16.0 * i / 200000.0);
    const double expected = std::pow(re, 0.687);
    worst = std::max(worst, std::abs(powPositive(re, 0.687) - expected) / expected);
  }
  EXPECT_LT(worst, 2e-14);
  EXPECT_EQ(powPositive(0.0, 0.687), 0.0);
  EXPECT_EQ(singleSphereDragFactor(0.0), 1.0);  // Stokes
  EXPECT_NEAR(singleSphereDragFactor(999.999), 1.0 + 0.15 * std::pow(999.999, 0.687), 1e-11);
  EXPECT_DOUBLE_EQ(singleSphereDragFactor(2000.0), 0.44 * 2000.0 / 24.0);  // Newton
  EXPECT_TRUE(std::isfinite(singleSphereDragFactor(1e300)));
}

/// The motion kernel takes Eq. (10) speeds from the models' vectorised speeds(); they equal the
/// per-cell speed() capped at u_fluc_max bit for bit, for both models, with and without a blend of
/// two frames, over empty, under- and over-packed cells and out-of-range fractions.
TEST(Kernel, VectorisedFluctuationSpeedsEqualThePerCellOnes) {
  std::mt19937_64 gen(17);
  std::uniform_real_distribution<double> fraction(-0.1, 1.1);
  const std::int64_t n = 5000;
  std::vector<float> tracer(n), recA(n), recB(n);
  for (std::int64_t c = 0; c < n; ++c) {
    tracer[c] = c % 7 == 0 ? 0.0f : float(fraction(gen));
    recA[c] = float(fraction(gen)), recB[c] = c % 11 == 0 ? recA[c] : float(fraction(gen));
  }
  const double d0 = 5e-4, dt = 0.005, cap = 0.05, blend = 0.37;  // LP peaks at 0.073 m/s here
  for (const std::string name : {"lichtenegger_pirker", "cfdem"}) {
    const auto model = FluctuationModelRegistry::create(name);
    for (const bool blended : {false, true}) {
      std::vector<float> out(2 * n, -1.0f);
      model->speeds(n, tracer.data(), recA.data(), blended ? recB.data() : nullptr, blended ? blend : 0.0, d0, dt,
                    cap, out.data() + 1, 2);
      std::int64_t capped = 0, moving = 0;
      for (std::int64_t c = 0; c < n; ++c) {
        const double rec = blended ? double(recA[c]) + blend * (double(recB[c]) - double(recA[c])) : double(recA[c]);
        const float expected = tracer[c] > 0.0f ? float(std::min(model->speed(tracer[c], rec, d0, dt), cap)) : 0.0f;
        ASSERT_EQ(out[2 * c + 1], expected) << name << " cell " << c;
        ASSERT_EQ(out[2 * c], -1.0f);  // the stride is kept
        capped += out[2 * c + 1] == float(cap), moving += out[2 * c + 1] > 0.0f;
      }
      EXPECT_GT(capped, 0) << name;  // the cap was reached, and
      EXPECT_GT(moving, capped) << name;  // speeds below it occurred
    }
  }
}

// substepsOfBlock(): blocks whose lanes all stay within one limit take a shortcut past the square
// roots; it must give what the exact count gives, on both sides of a Courant number of 1 and for NaN.
TEST(Kernel, SubstepCountOfABlockIsCeilOfTheCourantNumber) {
  using block::kBlock;
  constexpr double dt = 5e-3, limit = 0.01, kMax = 64.0;
  std::array<double, 65> lengths{};
  for (int n = 1; n <= 64; ++n) lengths[std::size_t(n)] = dt / double(n);
  auto count = [&](const std::vector<double>& courant, std::vector<double>& h, std::vector<std::int32_t>& left,
                   std::int64_t& extra, std::int64_t& capped) {
    const int m = int(courant.size());
    alignas(64) double ux[kBlock] = {}, uy[kBlock] = {}, uz[kBlock] = {};
    for (int k = 0; k < m; ++k) ux[k] = courant[std::size_t(k)] * limit / dt;  // |u| dt / limit = courant
    alignas(64) double hb[kBlock];
    alignas(64) std::int32_t lb[kBlock];
    const std::int32_t most =
        block::substepsOfBlock(ux, uy, uz, m, dt, 1.0 / limit, lengths.data(), kMax, hb, lb, extra, capped);
    h.assign(hb, hb + m), left.assign(lb, lb + m);
    return most;
  };
  std::vector<double> h;
  std::vector<std::int32_t> left;
  std::int64_t extra = 0, capped = 0;
  // Every lane slower than one limit: one sub-step of dt each.
  EXPECT_EQ(count(std::vector<double>(kBlock, 0.9), h, left, extra, capped), 0);
  for (int k = 0; k < kBlock; ++k) EXPECT_EQ(h[std::size_t(k)], dt) << k;
  for (int k = 0; k < kBlock; ++k) EXPECT_EQ(left[std::size_t(k)], 0) << k;
  EXPECT_EQ(extra, 0);
  // Every lane just below one limit, inside the shortcut's margin: the exact count, still one each.
  EXPECT_EQ(count(std::vector<double>(kBlock, 1.0 - 1e-12), h, left, extra, capped), 0);
  for (int k = 0; k < kBlock; ++k) EXPECT_EQ(h[std::size_t(k)], dt) << k;
  // Every lane just beyond one limit: none may take the shortcut.
  EXPECT_EQ(count(std::vector<double>(kBlock, 1.0 + 1e-9), h, left, extra, capped), 1);
  for (int k = 0; k < kBlock; ++k) EXPECT_EQ(left[std::size_t(k)], 1) << k;
  // Lanes around 1 and beyond kMax, and a NaN velocity (capped at kMax sub-steps).
  const std::vector<double> courant = {0.0, 1.0 - 1e-12, 1.0 + 1e-9, 2.5, 100.0,
                                       std::numeric_limits<double>::quiet_NaN(), 0.5};
  const std::vector<std::int32_t> expected = {1, 1, 2, 3, 64, 64, 1};
  extra = 0, capped = 0;
  EXPECT_EQ(count(courant, h, left, extra, capped), 63);
  for (std::size_t k = 0; k < courant.size(); ++k) {
    EXPECT_EQ(left[k], expected[k] - 1) << "courant " << courant[k];
    EXPECT_EQ(h[k], dt / double(expected[k])) << "courant " << courant[k];
  }
  EXPECT_EQ(extra, 0 + 0 + 1 + 2 + 63 + 63 + 0);
  EXPECT_EQ(capped, 2);
}

namespace {
/// Two tracers beside the right draft plate of the ProCell prism on 10 mm cells (the plate, x 0.0225 to
/// 0.0245, snapped to the face x = 0.025): one on the annulus's side half a millimetre past the face,
/// one on the tube's side. u_P^rec is 1 m/s upwards in the cells on the tube's side of that face and 0
/// beyond it. Returns their rise in one step of 5 ms.
std::array<double, 2> riseBesideThePlate(bool plates, bool vectorised) {
  Scene s = boxScene({0.2, 0.2, 0.2}, 0.01, 2, 0.005, {"transport", "walls"});
  s.apparatus = Scene{}.apparatus;  // ProCell
  if (plates) s.apparatus.draft_plates = DraftPlatesSpec{0.06, 0.045, 0.035, 0.002};
  s.process.bed_mass = Scene{}.process.bed_mass;
  const CartesianGrid grid = gridOf(s);
  const double face = 0.025;
  auto db = database(s, 3, s.rcfd.dt, [grid, face](int, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      f.alpha_p[std::size_t(c)] = 0.3f;
      f.u_p[3 * c + 1] = grid.cellCenter(ijk[0], ijk[1], ijk[2]).x() < face ? 1.0f : 0.0f;
    }
  });
  TracerSimulation sim(s, db, sequentialPath(3, 4), {5, 1, 0, vectorised});
  const double z = 0.5 * Apparatus(s.apparatus).depth();
  const Eigen::Vector3d annulus(face + 0.0005, 0.06, z), tube(0.0215, 0.06, z);
  sim.context().cloud.setPosition(0, annulus);
  sim.context().cloud.setPosition(1, tube);
  sim.step();  // may reorder the tracers: they are found by their ids
  const auto& ids = sim.cloud().id;
  const std::size_t a = ids[0] == 0 ? 0 : 1, t = 1 - a;
  return {sim.cloud().position(a).y() - annulus.y(), sim.cloud().position(t).y() - tube.y()};
}
}  // namespace

TEST(Kernel, TracersBesideAPlateTakeNoVelocityFromItsOtherSide) {
  // Trilinear between the centres x = 0.020 and 0.030 the annulus's tracer would rise at 0.45 m/s and
  // the tube's at 0.85 m/s; across the plate each keeps its own side's value, 0 and 1 m/s.
  for (const bool vectorised : {true, false}) {
    const auto rise = riseBesideThePlate(true, vectorised);
    EXPECT_EQ(rise[0], 0.0) << "vectorised " << vectorised;
    EXPECT_NEAR(rise[1], 0.005, 1e-9) << "vectorised " << vectorised;
  }
  const auto open = riseBesideThePlate(false, true);  // no plate: the stencil blends both sides
  EXPECT_NEAR(open[0], 0.45 * 0.005, 1e-8);
  EXPECT_NEAR(open[1], 0.85 * 0.005, 1e-8);
}

namespace {
/// One randomised case of the block path against ReferenceMotion: an apparatus (box, the ProCell prism,
/// with draft plates), a random smooth flow of u_P^rec and u_G^rec whose speeds span 0.2 to 400 m/s
/// (one sub-step to the 64 of the cap), alpha_P^rec from 0 (free flight) to 0.74, and a random choice of
/// Eq. (10)'s D0, free flight and the integrator. Returns the largest position difference [m] of a
/// tracer after `steps` steps, and the share of tracers that differ by more than 1e-9 m.
struct RandomCaseResult {
  double worst = 0.0, shareApart = 0.0;
  double meanMove = 0.0;  ///< mean distance a tracer moved over the steps [m]
  std::int64_t substeps = 0, freeFlying = 0, wallHits = 0, capped = 0;
  bool massWeighted = false;
  std::string description;
};

RandomCaseResult blockAgainstReferenceOnARandomCase(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  auto pick = [&rng](auto... values) {
    const std::array options{values...};
    return options[std::uniform_int_distribution<std::size_t>(0, options.size() - 1)(rng)];
  };
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<std::string> effects = {"transport", "walls", "tracer_volume_fraction"};
  const bool fluctuation = unit(rng) < 0.7, freeFlight = unit(rng) < 0.5;
  if (fluctuation) effects.push_back("fluctuation");
  if (freeFlight) effects.push_back("free_flight");
  Scene s = boxScene({0.2, 0.2, 0.2}, 0.01, 3000, 0.005, effects);
  const int apparatus = pick(0, 1, 2);  // box, prism, prism with plates
  if (apparatus > 0) {
    s.apparatus = Scene{}.apparatus;
    s.process.bed_mass = Scene{}.process.bed_mass;
    if (apparatus == 2) s.apparatus.draft_plates = DraftPlatesSpec{0.06, 0.045, 0.035, 0.002};
  }
  s.rcfd.d0 = pick(0.0, 1e-5, 1e-3, 1e-2);
  s.rcfd.integrator = pick(std::string("midpoint"), std::string("euler"));
  const double speed = pick(0.2, 2.0, 6.0, 40.0, 400.0);
  // With free flight, cells below free_flight_alpha (0.02) in every case.
  const double alphaMin = freeFlight ? pick(-0.3, -0.1) : pick(0.0, 0.1), alphaMax = pick(0.5, 0.74);
  // Three random Fourier modes per component.
  struct Mode {
    Eigen::Vector3d k;
    double phase, amplitude;
  };
  std::array<std::array<Mode, 3>, 4> modes;  // u_x, u_y, u_z, alpha
  for (auto& component : modes) {
    for (auto& m : component) {
      m.k = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) * 60.0;
      m.phase = 2.0 * std::numbers::pi * unit(rng);
      m.amplitude = unit(rng);
    }
  }
  auto field = [&modes](int component, const Eigen::Vector3d& p, double t) {
    double value = 0.0;
    for (const auto& m : modes[std::size_t(component)]) value += m.amplitude * std::sin(m.k.dot(p) + m.phase + 3.0 * t);
    return value / 3.0;  // in [-1, 1]
  };
  const bool massWeighted = unit(rng) < 0.5;
  if (massWeighted) s.rcfd.velocity_interpolation = "mass_weighted";
  const CartesianGrid grid = gridOf(s);
  auto db = database(s, 4, s.rcfd.dt, [&](int, double t, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      const Eigen::Vector3d p = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
      const double alpha = alphaMin + (alphaMax - alphaMin) * 0.5 * (1.0 + field(3, p, t));
      f.alpha_p[std::size_t(c)] = float(std::clamp(alpha, 0.0, alphaMax));
      for (int d = 0; d < 3; ++d) {
        f.u_p[3 * c + d] = float(speed * field(d, p, t));
        f.u_g[3 * c + d] = float(2.0 * speed * field((d + 1) % 3, p, t));
      }
    }
  });
  const std::int64_t steps = 10;
  TracerSimulation fast(s, db, sequentialPath(4, steps + 2), {seed, steps, 0, true});
  TracerSimulation reference(s, db, sequentialPath(4, steps + 2), {seed, steps, 0, false});
  RandomCaseResult r;
  std::vector<Eigen::Vector3d> start(fast.cloud().size());
  for (std::size_t i = 0; i < fast.cloud().size(); ++i) start[std::size_t(fast.cloud().id[i])] = fast.cloud().position(i);
  for (std::int64_t k = 0; k < steps; ++k) {
    fast.step();
    reference.step();
    const MotionStatistics& st = fast.motionStatistics();
    r.substeps += st.substeps, r.freeFlying += st.freeFlight, r.wallHits += st.wallHits, r.capped += st.substepCapped;
  }
  // Tracers are found by their ids (a sort by cell may order two runs differently).
  std::vector<std::size_t> referenceIndex(reference.cloud().size());
  for (std::size_t i = 0; i < reference.cloud().size(); ++i) referenceIndex[std::size_t(reference.cloud().id[i])] = i;
  std::int64_t apart = 0;
  for (std::size_t i = 0; i < fast.cloud().size(); ++i) {
    const std::size_t j = referenceIndex[std::size_t(fast.cloud().id[i])];
    const double d = (fast.cloud().position(i) - reference.cloud().position(j)).cwiseAbs().maxCoeff();
    r.worst = std::max(r.worst, d);
    apart += d > 1e-9;
    r.meanMove += (fast.cloud().position(i) - start[std::size_t(fast.cloud().id[i])]).norm() / double(fast.cloud().size());
  }
  r.shareApart = double(apart) / double(fast.cloud().size());
  r.massWeighted = massWeighted;
  r.description = "seed " + std::to_string(seed) + ": apparatus " + std::to_string(apparatus) + ", D0 " +
                  std::to_string(s.rcfd.d0) + ", " + s.rcfd.integrator + ", free flight " + std::to_string(freeFlight) +
                  ", fluctuation " + std::to_string(fluctuation) + ", speed " + std::to_string(speed) + " m/s, " +
                  s.rcfd.velocity_interpolation;
  return r;
}
}  // namespace

// The vectorised block path against the plain reference motion (ReferenceMotion) on randomised cases:
// every way a tracer moves (sub-steps up to the cap, free flight, walls, plates, both integrators) with
// the same random streams, in every variant of the block path this CPU runs (core/Isa.hpp). They may
// differ only where a fused multiply-add rounds differently: every tracer within 1e-9 m after 10 steps
// (the AVX2 variant agrees bit for bit). RCFD_KERNEL_RANDOM_CASES=N runs the first N cases (at least 4,
// which take every way of moving): tests/portable runs 4 on an emulated CPU.
TEST(Kernel, BlockPathMatchesTheReferenceMotionOnRandomCases) {
  const char* casesSet = std::getenv("RCFD_KERNEL_RANDOM_CASES");
  const std::uint64_t cases = casesSet ? std::max<std::uint64_t>(4, std::strtoull(casesSet, nullptr, 10)) : 16;
  int variants = 0;
  for (Isa isa : builtIsas()) {
    if (!cpuRuns(isa)) continue;
    ++variants;
    const test::ScopedVariable variant("RCFD_ISA", isaName(isa));  // every kernel built from here runs it
    std::int64_t substeps = 0, freeFlying = 0, wallHits = 0, capped = 0, massWeighted = 0;
    for (std::uint64_t seed = 1; seed <= cases; ++seed) {
      const RandomCaseResult r = blockAgainstReferenceOnARandomCase(seed);
      std::cout << isaName(isa) << ", " << r.description << ": moved " << r.meanMove
                << " m on average, worst difference " << r.worst << " m, " << 100.0 * r.shareApart << " % apart\n";
      EXPECT_LT(r.worst, 1e-9) << isaName(isa) << ", " << r.description << ": " << 100.0 * r.shareApart << " % apart";
      EXPECT_GT(r.meanMove, 1e-4) << r.description;
      substeps += r.substeps, freeFlying += r.freeFlying, wallHits += r.wallHits, capped += r.capped;
      massWeighted += r.massWeighted;
    }
    // The cases took every way of moving, with both velocity interpolations.
    EXPECT_GT(massWeighted, 0);
    EXPECT_LT(massWeighted, std::int64_t(cases));
    EXPECT_GT(substeps, 0);
    EXPECT_GT(freeFlying, 0);
    EXPECT_GT(wallHits, 0);
    EXPECT_GT(capped, 0);
  }
  EXPECT_GE(variants, 1);
}
