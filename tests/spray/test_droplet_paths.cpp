// Droplet paths through a database's frames (spray/DropletPaths.hpp): Eq. (11)-(14) across a layer of
// known thickness, where the droplets end, thread independence, and the option checks.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>

#include "spray/DropletPaths.hpp"
#include "core/Errors.hpp"
#include "spray/DepositionEfficiency.hpp"
#include "SprayTestSupport.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {

constexpr double kLayerBottom = 0.05, kLayerTop = 0.08;  // on cell faces of the 1 cm grid
constexpr double kLayerAlpha = 0.1;
constexpr double kRise = 2.0;  // [m/s]: half a cell in 2.5 ms, two sub-steps per 5 ms frame interval

/// The gas rises straight up through a resting layer of particles between kLayerBottom and kLayerTop.
std::shared_ptr<FieldDatabase> layerDatabase(const Scene& s, int frames) {
  const CartesianGrid grid = gridOf(s);
  return database(s, frames, 0.005, [grid](int, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      const double y = grid.cellCenter(ijk[0], ijk[1], ijk[2]).y();
      f.alpha_p[std::size_t(c)] = y > kLayerBottom && y < kLayerTop ? float(kLayerAlpha) : 0.0f;
      f.u_g[3 * c + 1] = float(kRise);
    }
  });
}

DropletPathOptions layerOptions() {
  DropletPathOptions o;
  o.launches = 4;
  o.pathsPerLaunch = 16;
  o.maxSeconds = 0.5;
  o.heights = {0.04, 0.09};
  return o;
}

}  // namespace

TEST(DropletPaths, ALayerPassesExpOfMinusItsOpticalDepth) {
  const Scene s = sprayBoxScene(100, kLayerAlpha, 0.2);
  const auto db = layerDatabase(s, 120);
  const auto r = dropletPaths(s, *db, layerOptions());
  // Eq. (11) with the exponential model over the layer's 3 cm at the rise speed: tau = 1.5 lambda a L / d_P.
  const double lambda = filterCoefficient({kLayerAlpha, kRise, 0.0}, depositionConstants(s));
  const double tau = 1.5 * lambda * kLayerAlpha * (kLayerTop - kLayerBottom) / s.particles.diameter;
  EXPECT_GT(tau, 1.0);  // a test of the depth, not of a transparent layer
  // Exact but for the frames' float alpha_P (0.1f is 1.5e-8 above 0.1).
  const double rel = 1e-7;
  EXPECT_NEAR(r.outlet, std::exp(-tau), rel * tau * std::exp(-tau));
  EXPECT_EQ(r.wall, 0.0);
  EXPECT_EQ(r.airborne, 0.0);
  EXPECT_NEAR(r.deposited, 1.0 - std::exp(-tau), rel * tau * std::exp(-tau));
  ASSERT_EQ(r.heights.size(), 2u);
  EXPECT_EQ(r.heights[0].reached, 1.0);
  EXPECT_EQ(r.heights[0].depositedBelow, 0.0);  // nothing below the layer
  EXPECT_EQ(r.heights[0].opticalDepthMedian, 0.0);
  EXPECT_NEAR(r.heights[1].depositedBelow, 1.0 - std::exp(-tau), rel * tau * std::exp(-tau));
  EXPECT_NEAR(r.heights[1].opticalDepthP10, tau, rel * tau);
  EXPECT_NEAR(r.heights[1].opticalDepthP90, tau, rel * tau);
  // Every launch instant passes the same share.
  EXPECT_NEAR(r.launchOversprayMedian, r.outlet, 1e-12);
  EXPECT_NEAR(r.launchOversprayMax, r.outlet, 1e-12);
}

TEST(DropletPaths, EveryDropletEndsSomewhereWhateverTheThreadCount) {
  const Scene s = sprayBoxScene(100, 0.05, 0.12);
  const auto db = sprayBoxDatabase(s, 0.05, 0.12, 1.5, 200);  // swaying gas: paths reach the side walls too
  DropletPathOptions o;
  o.launches = 8;
  o.pathsPerLaunch = 32;
  o.maxSeconds = 0.3;
  o.heights = {0.05, 0.1, 0.15};
  omp_set_num_threads(1);
  const auto one = dropletPaths(s, *db, o);
  omp_set_num_threads(2);
  const auto two = dropletPaths(s, *db, o);
  EXPECT_NEAR(one.outlet + one.wall + one.airborne + one.deposited, 1.0, 1e-12);
  EXPECT_GT(one.deposited, 0.0);
  EXPECT_GT(one.wall + one.outlet, 0.0);
  EXPECT_EQ(one.outlet, two.outlet);
  EXPECT_EQ(one.wall, two.wall);
  EXPECT_EQ(one.airborne, two.airborne);
  ASSERT_EQ(one.heights.size(), two.heights.size());
  for (std::size_t j = 0; j < one.heights.size(); ++j) {
    EXPECT_EQ(one.heights[j].depositedBelow, two.heights[j].depositedBelow);
    EXPECT_EQ(one.heights[j].opticalDepthMedian, two.heights[j].opticalDepthMedian);
    if (j > 0) { EXPECT_GE(one.heights[j].depositedBelow, one.heights[j - 1].depositedBelow); }
  }
}

TEST(DropletPaths, RefusesAFlightLongerThanTheFrames) {
  const Scene s = sprayBoxScene(100, kLayerAlpha, 0.2);
  const auto db = layerDatabase(s, 20);  // 0.1 s of frames
  auto o = layerOptions();
  try {
    dropletPaths(s, *db, o);
    FAIL() << "a 0.5 s flight through 0.1 s of frames was accepted";
  } catch (const InputError& e) {
    ASSERT_EQ(e.violations().size(), 1u);
    EXPECT_EQ(e.violations()[0].pointer, "/max_seconds");
  }
  o.maxSeconds = 0.05;
  o.launches = 0;
  EXPECT_THROW(dropletPaths(s, *db, o), InputError);
  o.launches = 100000;  // 1e9 paths: refused before anything is allocated
  o.pathsPerLaunch = 10000;
  try {
    dropletPaths(s, *db, o);
    FAIL() << "1e9 paths were accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.violations().at(0).pointer, "/paths_per_launch");
  }
}

TEST(DropletPaths, AFrameWithNaNIsAnInputErrorNotACrash) {
  // A cached database validates a frame when a path first reads it, inside the parallel loop.
  RawSpec spec;
  spec.nx = 10, spec.ny = 20, spec.nz = 4;
  spec.frames = 40;
  spec.dtRec = 0.005;
  spec.nanFrame = 2;
  const std::string path = tempPath("droplet-paths-nan.h5");
  writeRawDatabase(path, spec);
  const auto db = FieldDatabase::open(path, FrameStorage{std::int64_t(1) << 24});
  const Scene s = sprayBoxScene(100, kLayerAlpha, 0.2);
  DropletPathOptions o;
  o.launches = 2;
  o.pathsPerLaunch = 4;
  o.maxSeconds = 0.05;
  EXPECT_THROW(dropletPaths(s, *db, o), InputError);
}
