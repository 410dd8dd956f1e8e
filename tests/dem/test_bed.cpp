// Poured beds: packing fraction in a box, the ProCell V filled and settled, determinism across
// thread counts, history surviving list rebuilds.
#include <gtest/gtest.h>

#include <omp.h>
#include <algorithm>
#include <random>

#include "DemTestUtil.hpp"
#include "ProCellSection.hpp"
#include "cfddem/ApparatusWalls.hpp"
#include "cfddem/DemFilling.hpp"
#include "cfddem/DemParallel.hpp"
#include "core/Errors.hpp"

namespace rcfd {
namespace {

using Eigen::Vector3d;
using namespace demtest;

const QuietLog quiet;

/// Solid fraction of the box [lo, hi] from a regular grid of sample points.
double packingFraction(const DemParticles& p, const Vector3d& lo, const Vector3d& hi, int n) {
  long inside = 0, total = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const Vector3d x = lo + (hi - lo).cwiseProduct(Vector3d(i + 0.5, j + 0.5, k + 0.5) / n);
        ++total;
        for (std::size_t q = 0; q < p.size(); ++q)
          if ((p.x[q] - x).squaredNorm() < p.radius[q] * p.radius[q]) {
            ++inside;
            break;
          }
      }
  return static_cast<double>(inside) / total;
}

TEST(Bed, PouredBedPacksBetween058And064) {
  const double r = 1.5e-3;
  // The paper's contact parameters with a soft material (Y = 0.5 MPa) for a large time step; the
  // largest overlap in the bed stays near 1% of the radius.
  const DemMaterial m = material(r, 0.9, 0.75, 0.5, 0.24, 0.06, 0.05, 5e5, 1040.0);
  DemSettings s;
  s.time_step = 0.25 * m.rayleighTime();
  s.max_overlap_fraction = 1.0;
  s.rolling_model = "cdt";
  const Vector3d lo(-0.015, 0.0, 0.0), hi(0.015, 0.15, 0.03);
  DemSystem dem(m, DemWalls::box(lo, hi), s);
  FillOptions o;
  o.max_settle_time = 0.4;
  const long n = 1500;
  const FillResult res = fillAndSettle(dem, FillRegion{Vector3d(lo.x(), 0.05, lo.z()), hi}, n, o);
  ASSERT_EQ(res.inserted, n);
  EXPECT_TRUE(res.settled);
  std::vector<double> ys;
  for (const auto& x : dem.particles().x) ys.push_back(x.y());
  std::sort(ys.begin(), ys.end());
  const double top = ys[static_cast<std::size_t>(0.95 * ys.size())];
  // The core: 2.5 diameters from the side walls and floor, two below the rough top.
  const double d = 2 * r;
  const Vector3d clo = lo + Vector3d(2.5 * d, 2.5 * d, 2.5 * d);
  const Vector3d chi(hi.x() - 2.5 * d, top - 2 * d, hi.z() - 2.5 * d);
  ASSERT_GT(chi.y() - clo.y(), 3 * d);
  const double phi = packingFraction(dem.particles(), clo, chi, 40);
  RecordProperty("packing_fraction", std::to_string(phi));
  EXPECT_GT(phi, 0.58);
  EXPECT_LT(phi, 0.64);
}

TEST(Bed, AStopRequestEndsTheFillingAtTheNextDemStep) {
  // A cancelled database job must not wait for the whole filling (~40 s of wall time for quick.json,
  // hours for a large bed, where even a millisecond of simulated time takes minutes): the stop request
  // is polled before every DEM step, while batches fall and while the bed settles.
  const double r = 1.5e-3;
  const DemMaterial m = material(r, 0.9, 0.75, 0.5, 0.24, 0.06, 0.05, 5e5, 1040.0);
  DemSettings s;
  s.time_step = 0.25 * m.rayleighTime();
  const Vector3d lo(-0.015, 0.0, 0.0), hi(0.015, 0.15, 0.03);
  DemSystem dem(m, DemWalls::box(lo, hi), s);
  FillOptions o;
  std::vector<FillStage> stages;
  o.stage_started = [&](FillStage stage) { stages.push_back(stage); };
  o.stop_requested = [&] { return dem.time() >= 0.020; };  // after 20 ms of falling
  EXPECT_THROW(fillAndSettle(dem, FillRegion{Vector3d(lo.x(), 0.05, lo.z()), hi}, 1500, o), Cancelled);
  EXPECT_GE(dem.time(), 0.020);
  EXPECT_LT(dem.time(), 0.020 + s.time_step + 1e-12);
  EXPECT_EQ(stages, std::vector<FillStage>{FillStage::Inserting});
  // While settling too: the first batch alone takes 0.15 s to fall, so settling starts near 0.2 s.
  DemSystem settling(m, DemWalls::box(lo, hi), s);
  stages.clear();
  o.stop_requested = [&] { return !stages.empty() && stages.back() == FillStage::Settling; };
  EXPECT_THROW(fillAndSettle(settling, FillRegion{Vector3d(lo.x(), 0.05, lo.z()), hi}, 200, o), Cancelled);
  EXPECT_EQ(stages, (std::vector<FillStage>{FillStage::Inserting, FillStage::Settling}));
  // Without a request the same call fills everything.
  DemSystem full(m, DemWalls::box(lo, hi), s);
  o.stop_requested = [] { return false; };
  o.max_settle_time = 0.01;
  EXPECT_EQ(fillAndSettle(full, FillRegion{Vector3d(lo.x(), 0.05, lo.z()), hi}, 200, o).inserted, 200);
}

TEST(Bed, TheFillingReportsProgressThatMovesBeforeEveryDemStep) {
  // A database job's progress through the filling (hours on a large bed) comes from here: it must
  // move within each stage, never go back, and end at 1.
  const double r = 1.5e-3;
  const DemMaterial m = material(r, 0.9, 0.75, 0.5, 0.24, 0.06, 0.05, 5e5, 1040.0);
  DemSettings s;
  s.time_step = 0.25 * m.rayleighTime();
  const Vector3d lo(-0.015, 0.0, 0.0), hi(0.015, 0.15, 0.03);
  DemSystem dem(m, DemWalls::box(lo, hi), s);
  FillOptions o;
  o.max_settle_time = 0.05;
  std::vector<double> inserting, settling;
  std::vector<long> stepsAtCall;
  o.progress = [&](FillStage stage, double f) {
    (stage == FillStage::Inserting ? inserting : settling).push_back(f);
    stepsAtCall.push_back(dem.steps());
  };
  // A region too small for the bed in one batch: the progress must carry over from batch to batch.
  const FillResult result = fillAndSettle(dem, FillRegion{Vector3d(lo.x(), 0.1, lo.z()), hi}, 1500, o);
  ASSERT_GE(result.batches, 2);
  for (const auto* stage : {&inserting, &settling}) {
    ASSERT_FALSE(stage->empty());
    EXPECT_TRUE(std::is_sorted(stage->begin(), stage->end()));
    EXPECT_EQ(stage->back(), 1.0);
    EXPECT_GE(stage->front(), 0.0);
    const std::size_t between = std::count_if(stage->begin(), stage->end(), [](double f) { return f > 0.0 && f < 1.0; });
    EXPECT_GT(between, 100u);
  }
  EXPECT_EQ(inserting.front(), 0.0);
  // 1 only once the last batch has fallen.
  EXPECT_LT(*std::max_element(inserting.begin(), inserting.end() - 1), 1.0);
  // Before every DEM step: no step without a call before it, from the first to the last.
  EXPECT_EQ(stepsAtCall.front(), 0);
  EXPECT_EQ(stepsAtCall.back(), dem.steps());
  for (std::size_t k = 1; k < stepsAtCall.size(); ++k) ASSERT_LE(stepsAtCall[k] - stepsAtCall[k - 1], 1) << k;
  // The fraction goes up steadily with the DEM steps, not in one jump per batch.
  double largestJump = 0.0;
  for (std::size_t k = 1; k < inserting.size(); ++k) largestJump = std::max(largestJump, inserting[k] - inserting[k - 1]);
  EXPECT_LT(largestJump, 0.01);
}

TEST(Bed, SettleFractionFollowsTheTimeOrTheEnergyCriterionWhicheverIsAhead) {
  EXPECT_DOUBLE_EQ(fillSettleFraction(0.1, 0.5, 1e-2, 1e-2, 1e-6), 0.2);     // time alone
  EXPECT_NEAR(fillSettleFraction(0.01, 0.5, 1e-4, 1e-2, 1e-6), 0.5, 1e-12);   // halfway down on a log scale
  EXPECT_DOUBLE_EQ(fillSettleFraction(0.4, 0.5, 1e-4, 1e-2, 1e-6), 0.8);     // time ahead
  EXPECT_DOUBLE_EQ(fillSettleFraction(0.01, 0.5, 1e-6, 1e-2, 1e-6), 1.0);    // criterion met
  EXPECT_DOUBLE_EQ(fillSettleFraction(0.01, 0.5, 2e-2, 1e-2, 1e-6), 0.02);   // energy above its start
  EXPECT_DOUBLE_EQ(fillSettleFraction(0.7, 0.5, 1e-2, 1e-2, 1e-6), 1.0);     // time ran out
}

TEST(Bed, AStopRequestEndsTheInsertionOfALargeBatch) {
  // Inserting the parcels of a large bed is itself long (a million random positions, each tested
  // against the walls and its neighbours): the request is polled every kInsertionAttemptsPerPoll
  // attempts, before a single DEM step.
  const double r = 1.5e-3;
  const DemMaterial m = material(r, 0.9, 0.75, 0.5, 0.24, 0.06, 0.05, 5e5, 1040.0);
  DemSettings s;
  s.time_step = 0.25 * m.rayleighTime();
  const Vector3d lo(-0.15, 0.0, 0.0), hi(0.15, 0.6, 0.15);
  DemSystem dem(m, DemWalls::box(lo, hi), s);
  FillOptions o;
  int polls = 0;
  o.stop_requested = [&] { return ++polls > 3; };  // the batch's start, then after 4096 and 8192 attempts
  EXPECT_THROW(fillAndSettle(dem, FillRegion{Vector3d(lo.x(), 0.3, lo.z()), hi}, 100000, o), Cancelled);
  EXPECT_EQ(polls, 4);
  EXPECT_EQ(dem.steps(), 0);
  EXPECT_GT(dem.particles().size(), 0u);
  EXPECT_LE(dem.particles().size(), std::size_t(3 * kInsertionAttemptsPerPoll));
}

TEST(Bed, ProCellSettlesIntoTheVWithNothingOutside) {
  // 1.5 kg of the paper's particles as cg = 8 parcels (about 920), to keep the test short; cg = 3
  // (17,494 parcels) runs the same code in `rcfd-bench dem-procell` (docs/performance.md).
  Scene scene;
  scene.dem.coarse_graining = 8.0;
  ProCell cell;
  const DemMaterial m = DemMaterial::fromScene(scene);
  DemSettings s = DemSystem::settingsFromScene(scene);
  s.time_step = 0.25 * m.rayleighTime();
  s.max_overlap_fraction = 1.0;
  DemSystem dem(m, wallsFromSection(cell.edges(), cell.spec.depth), s);
  const long n = parcelsForBedMass(scene);
  EXPECT_NEAR(n, 1.5 / (512 * 1040 * M_PI / 6 * std::pow(1.8e-3, 3)), 1.0);
  FillOptions o;
  o.max_settle_time = 0.6;
  const FillResult res = fillAndSettle(dem, defaultFillRegion(cell.spec), n, o);
  EXPECT_EQ(res.inserted, n);
  double top = 0.0, mass = 0.0;
  for (std::size_t i = 0; i < dem.particles().size(); ++i) {
    const Vector3d& x = dem.particles().x[i];
    ASSERT_GT(cell.clearance(x), 0.5 * m.particle_radius) << "parcel " << i << " at " << x.transpose();
    EXPECT_GT(x.y(), 0.0) << "inside the inlet";
    top = std::max(top, x.y());
    mass += dem.particles().mass[i];
  }
  EXPECT_NEAR(mass, 1.5, 1.5 * 1e-3);
  EXPECT_LT(top, 0.15) << "the bed lies in the V, not in the freeboard";
}

std::vector<Vector3d> settleWithThreads(int threads) {
  const int before = omp_get_max_threads();
  omp_set_num_threads(threads);
  const DemMaterial m = material(1e-3, 0.9, 0.75, 0.5, 0.24, 0.06, 0.05, 5e6, 1040.0);
  DemSettings s;
  s.time_step = 0.2 * m.rayleighTime();
  s.max_overlap_fraction = 1.0;
  s.rolling_model = "cdt";
  s.skin_fraction = 0.01;  // frequent rebuilds: the history must be carried over identically
  DemSystem dem(m, DemWalls::box(Vector3d(-0.015, 0, 0), Vector3d(0.015, 0.05, 0.03)), s);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // A slightly compressed, jittered lattice with random velocities: contacts from the first step.
  for (int i = 0; i < 14; ++i)
    for (int j = 0; j < 11; ++j)
      for (int k = 0; k < 14; ++k)
        dem.addParticle(Vector3d(-0.0135 + 1.98e-3 * i + 2e-5 * u(rng), 1.0e-3 + 1.98e-3 * j,
                                 1.5e-3 + 1.98e-3 * k + 2e-5 * u(rng)),
                        0.05 * Vector3d(u(rng), u(rng), u(rng)));
  dem.run(200);
  EXPECT_GT(dem.neighbourList().builds(), 3) << "the list must be rebuilt during the run";
  EXPECT_GT(dem.lastStats().contacts, 300);
  omp_set_num_threads(before);
  return dem.particles().x;
}

TEST(Bed, BitIdenticalForOneAndTwoThreads) {
  const auto a = settleWithThreads(1);
  const auto b = settleWithThreads(2);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GE(a.size(), 2048u) << "large enough for the parallel loops to run";
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << "particle " << i;
}

/// The pairs (i < j) within r_i + r_j + skin, by brute force.
std::vector<std::pair<NeighbourList::Index, NeighbourList::Index>> pairsWithinReach(const DemParticles& p, double skin) {
  std::vector<std::pair<NeighbourList::Index, NeighbourList::Index>> out;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t k = i + 1; k < p.size(); ++k) {
      const double cut = p.radius[i] + p.radius[k] + skin;
      if ((p.x[k] - p.x[i]).squaredNorm() < cut * cut) out.emplace_back(NeighbourList::Index(i), NeighbourList::Index(k));
    }
  return out;
}

TEST(NeighbourList, ListsExactlyThePairsWithinReachHoweverLargeTheBoxAroundThem) {
  // A dense cluster in a tall box with a sparse fountain above it (fine linked cells, tens per
  // particle), then the same with two particles escaped 1 km away (cells coarsened to fit): the list
  // holds exactly the pairs a brute-force search finds, each row sorted, on one thread and on the
  // parallel path (more particles than kDemParallelMinParticles) with two and three.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double r = 1e-3, skin = 0.4 * r;
  DemParticles p;
  for (int i = 0; i < 3000; ++i) p.add(Vector3d(0.04 * u(rng), 0.04 * u(rng), 0.01 * u(rng)), Vector3d::Zero(), r * (0.8 + 0.4 * u(rng)), 1000.0);
  ASSERT_GE(long(p.size()), kDemParallelMinParticles);
  const int threads = omp_get_max_threads();
  for (int i = 0; i < 100; ++i) p.add(Vector3d(0.03 * u(rng), 0.03 + 0.5 * u(rng), 0.01 * u(rng)), Vector3d::Zero(), r, 1000.0);
  for (const bool escaped : {false, true}) {
    if (escaped) {
      p.add(Vector3d(1000.0, 0.0, 0.0), Vector3d::Zero(), r, 1000.0);
      p.add(Vector3d(0.0, -1000.0, 1000.0), Vector3d::Zero(), r, 1000.0);
    }
    const auto expected = pairsWithinReach(p, skin);
    EXPECT_GT(expected.size(), 1000u);
    for (int t : {1, 2, 3}) {
      omp_set_num_threads(t);
      NeighbourList list(skin);
      list.build(p, DemWalls());
      std::vector<std::pair<NeighbourList::Index, NeighbourList::Index>> listed;
      for (std::size_t i = 0; i < p.size(); ++i)
        for (auto q = list.row_start[i]; q < list.row_start[i + 1]; ++q) {
          if (q > list.row_start[i]) {
            EXPECT_LT(list.j[q - 1], list.j[q]);
          }
          listed.emplace_back(NeighbourList::Index(i), list.j[q]);
        }
      EXPECT_EQ(listed, expected) << (escaped ? "with particles far away" : "a bed and a fountain") << ", "
                                  << t << " threads";
    }
    omp_set_num_threads(threads);
    // Inside another parallel region without nesting (a team of one whatever omp_get_max_threads()
    // says) the list is the same.
    const int levels = omp_get_max_active_levels();
    omp_set_max_active_levels(1);
    std::size_t innerPairs = 0;
#pragma omp parallel num_threads(2)
    {
      NeighbourList list(skin);
      list.build(p, DemWalls());
      if (omp_get_thread_num() == 0) innerPairs = list.pairs();
    }
    omp_set_max_active_levels(levels);
    EXPECT_EQ(innerPairs, expected.size());
  }
}

TEST(NeighbourList, TangentialHistorySurvivesRebuilds) {
  // A locked sphere held on a 10 deg incline by static friction (tan 10 deg < mu) keeps its
  // tangential spring across forced list rebuilds: without the history it would creep downhill.
  const DemMaterial m = material(0.01, 0.9, 0.9, 0.5, 0.5);
  DemSettings s;
  s.time_step = 2e-5;
  s.skin_fraction = 1e-6;  // a tiny skin: the list is rebuilt whenever the sphere moves at all
  s.max_overlap_fraction = 1.0;
  const double th = 10.0 * M_PI / 180.0;
  s.gravity = Vector3d(9.81 * std::sin(th), -9.81 * std::cos(th), 0);
  DemSystem dem(m, DemWalls(), s);
  // two spheres: the upper one rests on the lower, frozen one (particle-particle history)
  dem.addParticle(Vector3d(0, 0, 0));
  dem.addParticle(Vector3d(0, 0.02, 0));
  auto& p = dem.particles();
  p.inv_mass[0] = 0.0;
  p.lockRotation(0);
  p.lockRotation(1);
  s.gravity = Vector3d(0, -9.81, 0);
  dem.setGravity(Vector3d(0, -9.81, 0));
  dem.run(5000);
  for (int k = 1; k <= 200; ++k) {
    const double a = th * k / 200;
    dem.setGravity(Vector3d(9.81 * std::sin(a), -9.81 * std::cos(a), 0));
    dem.run(10);
  }
  const long builds = dem.neighbourList().builds();
  const double x0 = p.x[1].x();
  dem.run(5000);
  EXPECT_GT(dem.neighbourList().builds(), builds + 10);
  // Elastic tangential displacement is about 2.5e-6 m; without history it would slide ~8 mm.
  EXPECT_LT(std::abs(p.x[1].x() - x0), 1e-5);
}

}  // namespace
}  // namespace rcfd

namespace rcfd {
namespace {

std::vector<Eigen::Vector3d> bedById(int sort_interval, long* builds, bool direct = false) {
  const DemMaterial m = demtest::material(1e-3, 0.9, 0.75, 0.5, 0.24, 0.06, 0.05, 5e6, 1040.0);
  DemSettings s;
  s.time_step = 0.2 * m.rayleighTime();
  s.max_overlap_fraction = 1.0;
  s.rolling_model = "cdt";
  s.skin_fraction = 0.02;
  s.sort_interval = sort_interval;
  s.serial_direct_accumulation = direct;
  DemSystem dem(m, DemWalls::box(Eigen::Vector3d(-0.01, 0, 0), Eigen::Vector3d(0.01, 0.05, 0.02)), s);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> pos;
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 14; ++j)
      for (int k = 0; k < 9; ++k)
        pos.emplace_back(-0.0088 + 1.98e-3 * i + 2e-5 * u(rng), 1.0e-3 + 1.98e-3 * j,
                         1.2e-3 + 1.98e-3 * k + 2e-5 * u(rng));
  std::shuffle(pos.begin(), pos.end(), rng);  // random order, as after random insertion
  for (const auto& x : pos) dem.addParticle(x, 0.05 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
  dem.run(300);
  *builds = dem.neighbourList().builds();
  std::vector<Eigen::Vector3d> out(dem.particles().size());
  for (std::size_t i = 0; i < out.size(); ++i) out[dem.particles().id[i]] = dem.particles().x[i];
  return out;
}

TEST(NeighbourList, SpatialSortingKeepsTheDynamics) {
  long builds_sorted = 0, builds_plain = 0;
  const auto sorted = bedById(1, &builds_sorted);
  const auto plain = bedById(0, &builds_plain);
  ASSERT_GE(sorted.size(), static_cast<std::size_t>(kDemSortMinParticles));
  EXPECT_GT(builds_sorted, 3);
  double worst = 0.0;
  for (std::size_t i = 0; i < sorted.size(); ++i) worst = std::max(worst, (sorted[i] - plain[i]).norm());
  // Only the order of floating-point sums differs; a lost or sign-flipped history would move
  // particles by micrometres.
  EXPECT_LT(worst, 1e-10) << "largest position difference [m]";
  RecordProperty("max_position_difference_m", ::testing::PrintToString(worst));
}

TEST(NeighbourList, SerialReferenceSchemeAgreesWithTheGather) {
  // The benchmark's reference (forces added straight into the particles, one thread) must be the
  // same physics as the deterministic per-pair gather, up to the order of the sums.
  const int before = omp_get_max_threads();
  omp_set_num_threads(1);
  long b1 = 0, b2 = 0;
  const auto gather = bedById(10, &b1, false);
  const auto direct = bedById(10, &b2, true);
  omp_set_num_threads(before);
  double worst = 0.0;
  for (std::size_t i = 0; i < gather.size(); ++i) worst = std::max(worst, (gather[i] - direct[i]).norm());
  EXPECT_LT(worst, 1e-10);
  EXPECT_GT(worst, 0.0) << "the sums run in another order, so the last bits differ: if not, the "
                           "reference scheme was not used";
}

}  // namespace
}  // namespace rcfd
