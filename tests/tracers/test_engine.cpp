// The engine's contracts: effects built only when asked for, clear errors, bit-identical results for
// any thread count and across checkpoint/resume, and robustness over a million steps.
#include <gtest/gtest.h>

#include "../BitIdentical.hpp"
#include <omp.h>

#include <cstring>

#include <nlohmann/json.hpp>

#include "core/Errors.hpp"
#include "tracers/CellIndex.hpp"
#include "tracers/CounterRng.hpp"
#include "TracerTestSupport.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {
std::shared_ptr<FieldDatabase> swirlingDatabase(const Scene& s, int frames) {
  const CartesianGrid grid = gridOf(s);
  return database(s, frames, s.rcfd.dt, [grid](int n, double t, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      const auto p = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
      f.alpha_p[std::size_t(c)] = float(0.3 + 0.25 * std::sin(40 * p.x() + 3 * t) * std::cos(30 * p.y()));
      f.u_p[3 * c] = float(0.5 * std::sin(20 * p.y() + n));
      f.u_p[3 * c + 1] = float(0.8 * std::cos(25 * p.x() - 2 * t));
      f.u_p[3 * c + 2] = float(0.1 * std::sin(n + 50 * p.z()));
      f.u_g[3 * c + 1] = 2.0f;
    }
  });
}

Scene fullTracerScene() {
  Scene s = boxScene({0.1, 0.15, 0.04}, 0.01, 5000, 0.005,  // above kParallelThreshold
                     {"transport", "walls", "fluctuation", "free_flight", "tracer_volume_fraction", "probes",
                      "residence_time", "field_average"},
                     0.3);
  s.rcfd.d0 = 5e-4;
  s.probes = {{"a", Vec3(0.0, 0.05, 0.02)}, {"b", Vec3(0.03, 0.1, 0.01)}};
  s.spray.spray_zone.apex = Vec3(0.0, 0.0, 0.02);
  s.spray.spray_zone.y_min = 0.02;
  s.spray.spray_zone.y_max = 0.1;
  return s;
}

struct RunResult {
  TracerCloud cloud;
  nlohmann::json summary;
};

// Re-sorted by cell every 7 steps (the default is 100): the runs below cross several sorts, and the
// checkpoint at step 23 falls between two.
constexpr std::int64_t kTestSortInterval = 7;

RunResult runFor(const Scene& s, std::shared_ptr<FieldDatabase> db, std::int64_t steps, int threads,
                 std::int64_t checkpointAt = -1, std::int64_t sortInterval = kTestSortInterval) {
  omp_set_num_threads(threads);
  RecurrencePath path = sequentialPath(db->frameCount(), steps + 2);
  const std::string checkpoint = tempPath("engine-checkpoint.h5");
  const TracerRunSettings settings{42, steps, 10, true, sortInterval};
  TracerSimulation sim(s, db, path, settings);
  std::unique_ptr<TracerSimulation> resumed;
  TracerSimulation* active = &sim;
  for (std::int64_t k = 0; k < steps; ++k) {
    if (k == checkpointAt) {
      sim.saveCheckpoint(checkpoint);
      resumed = std::make_unique<TracerSimulation>(s, db, path, settings);
      resumed->loadCheckpoint(checkpoint);
      active = resumed.get();
    }
    active->step();
  }
  RunResult r{active->cloud(), {}};
  h5::File out(tempPath("engine-result.h5"), h5::File::Mode::Create);
  active->writeResults(out, r.summary);
  omp_set_num_threads(2);
  return r;
}

using rcfd::test::bitIdentical;
}  // namespace

TEST(Effects, NotAskedForIsNotBuiltNorAllocated) {
  Scene s = boxScene({0.1, 0.1, 0.1}, 0.01, 1000, 0.005, {"transport", "walls"});
  auto db = swirlingDatabase(s, 4);
  TracerSimulation lean(s, db, sequentialPath(4, 20), {1, 10, 0});
  EXPECT_EQ(lean.effectNames(), (std::vector<std::string>{"transport", "walls"}));
  EXPECT_EQ(lean.effect("tracer_volume_fraction"), nullptr);
  EXPECT_EQ(lean.effect("residence_time"), nullptr);
  EXPECT_EQ(lean.allocatedBytes("field_average"), 0u);
  EXPECT_TRUE(lean.context().tracerAlpha.empty());
  EXPECT_TRUE(lean.context().tracerCount.empty());
  EXPECT_TRUE(lean.context().tracerCell.empty());
  EXPECT_EQ(lean.cloud().size(), 1000u);

  s.effects = {"transport", "walls", "tracer_volume_fraction", "field_average"};
  TracerSimulation rich(s, db, sequentialPath(4, 20), {1, 10, 0});
  EXPECT_NE(rich.effect("tracer_volume_fraction"), nullptr);
  EXPECT_EQ(rich.context().tracerAlpha.size(), std::size_t(db->grid().cellCount()));
  EXPECT_GE(rich.allocatedBytes("field_average"), 2 * std::size_t(db->grid().cellCount()) * sizeof(double));
}

TEST(Effects, UnknownNameListsTheValidOnes) {
  Scene s = boxScene({0.1, 0.1, 0.1}, 0.02, 10, 0.005, {"transport", "walls", "teleport"});
  auto db = swirlingDatabase(s, 4);
  try {
    TracerSimulation sim(s, db, sequentialPath(4, 20), {1, 10, 0});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    ASSERT_EQ(e.violations().size(), 1u);
    EXPECT_EQ(e.violations()[0].pointer, "/effects/2");
    EXPECT_NE(e.violations()[0].message.find("teleport"), std::string::npos);
    EXPECT_NE(e.violations()[0].message.find("fluctuation"), std::string::npos);
  }
}

TEST(Effects, MissingDependencyIsRefused) {
  Scene s = boxScene({0.1, 0.1, 0.1}, 0.02, 10, 0.005, {"transport", "walls", "fluctuation"});
  auto db = swirlingDatabase(s, 4);
  try {
    TracerSimulation sim(s, db, sequentialPath(4, 20), {1, 10, 0});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("needs \"tracer_volume_fraction\""), std::string::npos) << e.what();
  }
}

TEST(Determinism, OneAndTwoThreadsAreBitIdentical) {
  const Scene s = fullTracerScene();
  auto db = swirlingDatabase(s, 12);
  const RunResult one = runFor(s, db, 50, 1);
  const RunResult two = runFor(s, db, 50, 2);
  EXPECT_TRUE(bitIdentical(one.cloud.x, two.cloud.x));
  EXPECT_TRUE(bitIdentical(one.cloud.y, two.cloud.y));
  EXPECT_TRUE(bitIdentical(one.cloud.z, two.cloud.z));
  EXPECT_TRUE(bitIdentical(one.cloud.vy, two.cloud.vy));
  EXPECT_EQ(one.summary.dump(), two.summary.dump());
  EXPECT_GT(one.summary["residence_time"]["stays"].get<int>(), 0);
}

TEST(Determinism, ResumedRunEqualsUninterruptedRun) {
  const Scene s = fullTracerScene();
  auto db = swirlingDatabase(s, 12);
  const RunResult straight = runFor(s, db, 50, 2);
  const RunResult resumed = runFor(s, db, 50, 2, 23);
  EXPECT_TRUE(bitIdentical(straight.cloud.x, resumed.cloud.x));
  EXPECT_TRUE(bitIdentical(straight.cloud.z, resumed.cloud.z));
  EXPECT_EQ(straight.summary.dump(), resumed.summary.dump());
}

TEST(Determinism, ACheckpointWithDamagedTracerIdsIsRefused) {
  const Scene s = fullTracerScene();
  auto db = swirlingDatabase(s, 12);
  const RecurrencePath path = sequentialPath(db->frameCount(), 12);
  TracerSimulation sim(s, db, path, {42, 10, 0});
  for (int k = 0; k < 3; ++k) sim.step();
  const std::string checkpoint = tempPath("engine-damaged-ids.h5");
  sim.saveCheckpoint(checkpoint);
  {
    h5::File f(checkpoint, h5::File::Mode::ReadWrite);
    std::vector<std::int64_t> id = f.readInt64s("/cloud/id");
    id[1] = id[0];  // one tracer twice, another missing
    f.write("/cloud/id", id);
  }
  TracerSimulation resumed(s, db, path, {42, 10, 0});
  try {
    resumed.loadCheckpoint(checkpoint);
    FAIL() << "a damaged id list was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/cloud/id"), std::string::npos) << e.what();
  }
}

TEST(Determinism, SortingTheTracersChangesNoResult) {
  // Every tracer draws from its own stream (by id) and the per-cell counts are integers, so the order
  // the tracers are stored in is invisible: never sorted and sorted every 7 steps agree bit for bit.
  const Scene s = fullTracerScene();
  auto db = swirlingDatabase(s, 12);
  const RunResult sorted = runFor(s, db, 50, 2);
  const RunResult unsorted = runFor(s, db, 50, 2, -1, 0);
  EXPECT_NE(sorted.cloud.id, unsorted.cloud.id);  // the sort did reorder
  EXPECT_TRUE(bitIdentical(sorted.cloud.inIdOrder(sorted.cloud.x), unsorted.cloud.inIdOrder(unsorted.cloud.x)));
  EXPECT_TRUE(bitIdentical(sorted.cloud.inIdOrder(sorted.cloud.z), unsorted.cloud.inIdOrder(unsorted.cloud.z)));
  EXPECT_TRUE(bitIdentical(sorted.cloud.inIdOrder(sorted.cloud.vy), unsorted.cloud.inIdOrder(unsorted.cloud.vy)));
  EXPECT_EQ(sorted.summary.dump(), unsorted.summary.dump());
}

TEST(Determinism, KernelsTracerCellsEqualRecomputedOnes) {
  // The motion kernel hands the cells of the positions it wrote to the next step's
  // tracer_volume_fraction; a run that makes it recompute them every step must be the same bit for bit.
  const Scene s = fullTracerScene();
  auto db = swirlingDatabase(s, 12);
  const std::int64_t steps = 30;
  const RecurrencePath path = sequentialPath(db->frameCount(), steps + 2);
  TracerSimulation handedOver(s, db, path, {42, steps, 10});
  TracerSimulation recomputed(s, db, path, {42, steps, 10});
  for (std::int64_t k = 0; k < steps; ++k) {
    handedOver.step();
    const TracerSimulation& view = handedOver;  // const access keeps the kernel's cells
    const TracerContext& ctx = view.context();
    ASSERT_EQ(ctx.nextTracerCellStep, ctx.step);
    std::vector<std::int32_t> cells(view.cloud().size());
    CellIndexer(ctx.grid).cellsOf(int(cells.size()), view.cloud().x.data(), view.cloud().y.data(),
                                  view.cloud().z.data(), cells.data());
    ASSERT_EQ(cells, ctx.nextTracerCell) << "step " << k;
    recomputed.context();  // mutable access: the cells are forgotten and recomputed
    ASSERT_EQ(recomputed.context().nextTracerCellStep, -1);
    recomputed.step();
  }
  EXPECT_TRUE(bitIdentical(handedOver.cloud().x, recomputed.cloud().x));
  EXPECT_TRUE(bitIdentical(handedOver.cloud().y, recomputed.cloud().y));
  EXPECT_TRUE(bitIdentical(handedOver.cloud().z, recomputed.cloud().z));
}

TEST(Robustness, AMillionStepsThroughRandomFieldsLoseNothing) {
  // Random fields with velocities up to 40 m/s and random alpha (incl. empty and over-packed cells) in
  // the ProCell apparatus with draft plates: every tracer stays inside and finite.
  Scene s;
  s.apparatus.draft_plates = DraftPlatesSpec{};
  s.grid.cell_size = Vec3(0.025, 0.025, 0.025);
  s.rcfd.dt = 0.005;
  s.rcfd.tracers = 6;
  s.rcfd.d0 = 1e-2;
  s.effects = {"transport", "walls", "fluctuation", "free_flight", "tracer_volume_fraction"};
  Apparatus apparatus(s.apparatus);
  const CartesianGrid grid = makeGrid(apparatus, s.grid);
  const auto open = openFractions(apparatus, grid);
  std::vector<float> fluid(open.begin(), open.end());
  const int frames = 16;
  auto db = makeAnalyticDatabase(grid, fluid, s.rcfd.dt, frames, [&](int n, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      CounterRng rng(99, RngPurpose::Test, std::uint64_t(c), std::uint64_t(n));
      f.alpha_p[std::size_t(c)] = float(rng.uniform() < 0.2 ? 0.0 : 0.7 * rng.uniform());
      for (int d = 0; d < 3; ++d) f.u_p[3 * c + d] = float(80.0 * (rng.uniform() - 0.5));
      for (int d = 0; d < 3; ++d) f.u_g[3 * c + d] = float(60.0 * (rng.uniform() - 0.5));
    }
  });
  const std::int64_t steps = 1000000;
  RecurrencePath path;
  path.frames.resize(std::size_t(steps + 2));
  for (std::size_t k = 0; k < path.frames.size(); ++k) path.frames[k] = int(mix64(k) % frames);
  omp_set_num_threads(1);  // six tracers: threads would only add barrier overhead
  TracerSimulation sim(s, db, path, {8, steps, 0});
  for (std::int64_t k = 0; k < steps; ++k) {
    sim.step();
    if (k % 997 == 0) {
      for (std::size_t i = 0; i < sim.cloud().size(); ++i) {
        const auto p = sim.cloud().position(i);
        ASSERT_TRUE(p.allFinite()) << "step " << k;
        ASSERT_TRUE(sim.cloud().velocity(i).allFinite()) << "step " << k;
        ASSERT_GE(apparatus.signedDistance(p), -1e-9) << "tracer " << i << " escaped at step " << k;
      }
    }
  }
  omp_set_num_threads(2);
  EXPECT_EQ(sim.cloud().size(), 6u);
  for (std::size_t i = 0; i < sim.cloud().size(); ++i) EXPECT_GE(apparatus.signedDistance(sim.cloud().position(i)), -1e-9);
}
