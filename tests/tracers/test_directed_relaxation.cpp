// directed_relaxation: the directed relaxation of tracer over- and under-packing. On a bed at rest
// (u_P^rec = 0, alpha_P^rec = 0.3 everywhere) whose tracers start in its left half only, the directed
// flux fills the empty half below the counting floor, stably for D0 dt / h^2 up to 5, where Eq. (10)
// (which moves only tracers of over-packed cells, in random directions) leaves the RMS well above it;
// tracers already spread as
// alpha_P^rec says stay spread; the tracer count is kept, results are bit-identical for 1 and 2 threads
// and across a resume, and D0 = 0 leaves the tracers where they are.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>

#include "TracerTestSupport.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {

constexpr double kAlpha = 0.3;

/// A 0.1 x 0.1 x 0.02 m box of 1 cm cells, the bed at rest at alpha_P^rec = 0.3; frame 0 (which places
/// the tracers) holds the whole bed in the left half when `leftHalfFirst`.
struct RestingBox {
  Scene scene;
  std::shared_ptr<FieldDatabase> db;
  RestingBox(std::vector<std::string> effects, double d0, bool leftHalfFirst, long tracers = 6000) {
    scene = boxScene({0.1, 0.1, 0.02}, 0.01, tracers, 0.005, std::move(effects), kAlpha);
    scene.rcfd.d0 = d0;
    const CartesianGrid grid = gridOf(scene);
    db = database(scene, 400, scene.rcfd.dt, [=](int n, double, FieldFrame& f) {
      for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
        const auto ijk = grid.cellIjk(c);
        const bool left = grid.cellCenter(ijk[0], ijk[1], ijk[2]).x() < 0.0;
        f.alpha_p[std::size_t(c)] = float(n == 0 && leftHalfFirst ? (left ? 2.0 * kAlpha : 0.0) : kAlpha);
      }
    });
  }
};

/// RMS over the cells of the tracers' alpha_P against 0.3, and the counting floor: the RMS of Poisson
/// counts with the mean of a cell, sqrt(alpha_one_tracer * 0.3).
struct Spread {
  double rms = 0.0, floor = 0.0;
};
Spread spreadOf(const TracerSimulation& sim) {
  const auto& ctx = sim.context();
  const double perTracer = sim.cloud().particlesPerTracer * sim.cloud().particleVolume / ctx.openVolume[0];
  std::vector<std::int32_t> count(ctx.openVolume.size(), 0);
  for (std::size_t i = 0; i < sim.cloud().size(); ++i) ++count[std::size_t(ctx.grid.flatIndexOf(sim.cloud().position(i)))];
  double sum = 0.0;
  for (const auto n : count) sum += std::pow(double(n) * perTracer - kAlpha, 2);
  return {std::sqrt(sum / double(count.size())), std::sqrt(perTracer * kAlpha)};
}

std::unique_ptr<TracerSimulation> runBox(const RestingBox& box, std::int64_t steps, int threads = 2,
                                         std::int64_t checkpointAt = -1) {
  return runSteps(box.scene, box.db, 11, steps, threads, checkpointAt, "relaxation-checkpoint.h5");
}

const std::vector<std::string> kDirected = {"transport", "walls", "tracer_volume_fraction", "directed_relaxation"};
const std::vector<std::string> kEq10 = {"transport", "walls", "tracer_volume_fraction", "fluctuation"};

}  // namespace

TEST(DirectedRelaxation, FillsAnEmptyHalfBelowTheCountingFloorAndStaysStableForLargeD0) {
  const RestingBox start(kDirected, 1e-2, true);
  const Spread before = spreadOf(*runBox(start, 0));
  EXPECT_GT(before.rms, 0.25);  // the left half at 0.6, the right empty
  // 1 s: a few diffusion times (0.05 m)^2 / D0 at 1e-2; at 1e-1, D0 dt / h^2 = 5, where an explicit
  // step or a cell-centred gradient oscillates.
  for (const double d0 : {1e-2, 1e-1}) {
    const RestingBox directed(kDirected, d0, true);
    const auto sim = runBox(directed, 200);
    const Spread after = spreadOf(*sim);
    // Below Poisson counting: the flux follows the counting noise too and evens it out.
    EXPECT_LT(after.rms, after.floor) << "D0 " << d0 << ": RMS " << after.rms << " floor " << after.floor;
    EXPECT_EQ(sim->cloud().size(), std::size_t(6000));
  }
  // Eq. (10) with the same D0 moves only the over-packed tracers, in random directions: after the same
  // time it is still far from alpha_P^rec.
  const RestingBox eq10(kEq10, 1e-2, true);
  const Spread random = spreadOf(*runBox(eq10, 200));
  EXPECT_GT(random.rms, 2.0 * random.floor) << "Eq. (10) RMS " << random.rms;
}

TEST(DirectedRelaxation, TracersSpreadAsAlphaRecStaySpread) {
  const RestingBox box(kDirected, 1e-2, false);
  const Spread before = spreadOf(*runBox(box, 0));
  const auto sim = runBox(box, 200);
  const Spread after = spreadOf(*sim);
  EXPECT_LT(after.rms, 1.2 * before.rms) << "before " << before.rms << " after " << after.rms;
  EXPECT_LT(after.rms, 1.5 * after.floor);
}

TEST(DirectedRelaxation, BitIdenticalForOneAndTwoThreadsAndAcrossAResume) {
  const RestingBox box(kDirected, 3e-2, true, 20000);  // above the parallel threshold
  const auto two = runBox(box, 60, 2);
  const auto one = runBox(box, 60, 1);
  const auto resumed = runBox(box, 60, 2, 23);
  EXPECT_EQ(two->cloud().x, one->cloud().x);
  EXPECT_EQ(two->cloud().y, one->cloud().y);
  EXPECT_EQ(two->cloud().x, resumed->cloud().x);
  EXPECT_EQ(two->cloud().z, resumed->cloud().z);
}

TEST(DirectedRelaxation, ZeroD0LeavesTheTracersWhereTheyAre) {
  const RestingBox box(kDirected, 0.0, true);
  const auto start = runBox(box, 0);
  const auto sim = runBox(box, 50);
  EXPECT_EQ(start->cloud().inIdOrder(start->cloud().x), sim->cloud().inIdOrder(sim->cloud().x));
  EXPECT_EQ(start->cloud().inIdOrder(start->cloud().y), sim->cloud().inIdOrder(sim->cloud().y));
}

TEST(DirectedRelaxation, AllocatesOnlyWhenListed) {
  const RestingBox with(kDirected, 1e-2, false);
  const auto listed = runBox(with, 1);
  EXPECT_GT(listed->allocatedBytes("directed_relaxation"), 6000 * 3 * sizeof(float));
  EXPECT_EQ(listed->context().streamVelocity[0].size(), std::size_t(6000));
  const RestingBox without(kEq10, 1e-2, false);
  const auto plain = runBox(without, 1);
  EXPECT_EQ(plain->allocatedBytes("directed_relaxation"), 0u);
  EXPECT_TRUE(plain->context().streamVelocity[0].empty());
}
