// Recurrence matrix (Eq. 6-7): Gram form against a naive double loop, blocking, norms, properties,
// periodic fields, storage in the database.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <vector>

#include "../fields/FieldTestUtil.hpp"
#include "core/Errors.hpp"
#include "recurrence/RecurrenceMatrix.hpp"
#include "recurrence/RecurrencePlot.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {

// D(i, j) straight from Eq. (6): sum over cells of V_open,c (g_i - g_j)^2 with g = alpha_G = 1 - alpha_P
// (the paper's field; the implementation uses alpha_P), or the L1 / max forms.
Eigen::MatrixXd naiveDistances(const FieldDatabase& db, const std::string& field, RecurrenceNorm norm) {
  const FieldComponent fc = parseFieldComponent(field);
  const int n = db.frameCount();
  const double v = db.grid().cellVolume();
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const auto a = db.frame(i), b = db.frame(j);
      double d = 0.0;
      for (std::int64_t c = 0; c < db.grid().cellCount(); ++c) {
        const double w = db.fluidFraction()[std::size_t(c)] * v;
        if (w <= 0.0) continue;
        double gi = fc.value(*a, c), gj = fc.value(*b, c);
        if (field == "alpha_p") gi = 1.0 - gi, gj = 1.0 - gj;  // alpha_G
        const double diff = gi - gj;
        if (norm == RecurrenceNorm::L2) d += w * diff * diff;
        else if (norm == RecurrenceNorm::L1) d += w * std::abs(diff);
        else d = std::max(d, std::abs(diff));
      }
      D(i, j) = d;
    }
  return D;
}

Eigen::MatrixXd naiveR(const Eigen::MatrixXd& D) { return (1.0 - D.array() / D.maxCoeff()).matrix(); }

std::shared_ptr<FieldDatabase> wavyDb(int frames = 40, int nx = 6, int ny = 5, int nz = 4) {
  const CartesianGrid g = smallGrid(nx, ny, nz);
  return makeAnalyticDatabase(g, variedFluid(g), 0.005, frames, [&](int n, double, FieldFrame& f) { wavyFrame(g, n, f); });
}

}  // namespace

TEST(RecurrenceMatrix, GramEqualsNaiveDoubleLoop) {
  auto db = wavyDb();
  const Eigen::MatrixXd expected = naiveR(naiveDistances(*db, "alpha_p", RecurrenceNorm::L2));
  for (GramPrecision gram : {GramPrecision::Double, GramPrecision::Auto}) {
    RecurrenceOptions o;
    o.gram = gram;
    const RecurrenceMatrix m = computeRecurrenceMatrix(*db, o);
    EXPECT_EQ(m.frameBlocks, 1);
    EXPECT_LT((m.R.cast<double>() - expected).cwiseAbs().maxCoeff(), 1e-6);
    if (gram == GramPrecision::Auto) {
      // Either the float result passed its spot check or it was replaced by the double one.
      EXPECT_EQ(m.gramUsed, m.autoFellBack ? GramPrecision::Double : GramPrecision::FloatChunked);
      EXPECT_EQ(m.autoFellBack, m.spotCheckError > o.autoTolerance);
    }
  }
}

// Auto falls back to double when the spot check fails (forced here with a zero tolerance).
TEST(RecurrenceMatrix, AutoFallsBackToDoubleWhenTheSpotCheckFails) {
  auto db = wavyDb(30);
  RecurrenceOptions o;
  o.autoTolerance = 0.0;
  const RecurrenceMatrix automatic = computeRecurrenceMatrix(*db, o);
  o.gram = GramPrecision::Double;
  const RecurrenceMatrix exact = computeRecurrenceMatrix(*db, o);
  EXPECT_TRUE(automatic.autoFellBack);
  EXPECT_EQ(automatic.gramUsed, GramPrecision::Double);
  EXPECT_GT(automatic.spotCheckError, 0.0);
  EXPECT_EQ(automatic.R, exact.R);
}

TEST(RecurrenceMatrix, OneAndTwoThreadsGiveTheSameMatrixBitForBit) {
  // One tile holding every frame: the tile loop runs on one thread, and its GEMMs are large enough for
  // a parallelising BLAS to split them, which would change the order of the sums with the threads.
  auto db = wavyDb(96, 20, 16, 8);
  for (GramPrecision gram : {GramPrecision::Double, GramPrecision::FloatChunked}) {
    RecurrenceOptions o;
    o.gram = gram;
    o.tileFrames = 1000;
    omp_set_num_threads(1);
    const RecurrenceMatrix one = computeRecurrenceMatrix(*db, o);
    omp_set_num_threads(2);
    const RecurrenceMatrix two = computeRecurrenceMatrix(*db, o);
    ASSERT_EQ(one.R.size(), two.R.size());
    EXPECT_TRUE(std::equal(one.R.data(), one.R.data() + one.R.size(), two.R.data()));
  }
}

TEST(RecurrenceMatrix, BlockedOverFramesEqualsUnblocked) {
  auto db = wavyDb(37);
  const Eigen::MatrixXd expected = naiveR(naiveDistances(*db, "alpha_p", RecurrenceNorm::L2));
  std::int64_t openCells = 0;
  for (float f : db->fluidFraction()) openCells += f > 0.0f;
  for (GramPrecision gram : {GramPrecision::Double, GramPrecision::FloatChunked}) {
    RecurrenceOptions o;
    o.gram = gram;
    o.memoryBudgetBytes = 2 * openCells * 8 * 7;  // 7 double (14 float) frames per block
    o.tileFrames = 3;
    const RecurrenceMatrix m = computeRecurrenceMatrix(*db, o);
    EXPECT_EQ(m.frameBlocks, gram == GramPrecision::Double ? 6 : 3);
    EXPECT_LT((m.R.cast<double>() - expected).cwiseAbs().maxCoeff(), 1e-6);
  }
}

TEST(RecurrenceMatrix, FloatChunkedGramMeetsTheTolerance) {
  auto db = wavyDb(37, 20, 15, 10);  // 3000 cells: two float chunks
  const Eigen::MatrixXd expected = naiveR(naiveDistances(*db, "alpha_p", RecurrenceNorm::L2));
  RecurrenceOptions o;
  o.gram = GramPrecision::FloatChunked;
  o.tileFrames = 8;
  const RecurrenceMatrix m = computeRecurrenceMatrix(*db, o);
  EXPECT_LT((m.R.cast<double>() - expected).cwiseAbs().maxCoeff(), 1e-6);
}

TEST(RecurrenceMatrix, SymmetricUnitDiagonalInUnitRangeZeroAtMostDistantPair) {
  auto db = wavyDb(30);
  const RecurrenceMatrix m = computeRecurrenceMatrix(*db);
  EXPECT_EQ(m.R, m.R.transpose());
  for (int i = 0; i < 30; ++i) EXPECT_EQ(m.R(i, i), 1.0f);
  EXPECT_GE(m.R.minCoeff(), 0.0f);
  EXPECT_LE(m.R.maxCoeff(), 1.0f);
  Eigen::Index i, j;
  naiveDistances(*db, "alpha_p", RecurrenceNorm::L2).maxCoeff(&i, &j);
  EXPECT_EQ(m.R(i, j), 0.0f);
  EXPECT_GT(m.normalisation, 0.0);
}

TEST(RecurrenceMatrix, L1AndMaxNormsEqualNaiveLoops) {
  auto db = wavyDb(23);
  for (RecurrenceNorm norm : {RecurrenceNorm::L1, RecurrenceNorm::Max}) {
    const Eigen::MatrixXd expected = naiveR(naiveDistances(*db, "alpha_p", norm));
    for (std::int64_t budget : {std::int64_t(1) << 30, std::int64_t(2000)}) {  // one block; many blocks
      RecurrenceOptions o;
      o.norm = norm;
      o.memoryBudgetBytes = budget;
      o.tileFrames = 4;
      const RecurrenceMatrix m = computeRecurrenceMatrix(*db, o);
      EXPECT_LT((m.R.cast<double>() - expected).cwiseAbs().maxCoeff(), 1e-6) << toString(norm) << " budget " << budget;
      if (budget == 2000) {
        EXPECT_GT(m.frameBlocks, 1);
      }
    }
  }
}

// Every tile pair of every block pair lands where it belongs, for every norm, arithmetic, blocking and
// tiling, in the parallel loop too: on frames of quarter-integer values with perfect-square weights
// every sum is exact in float and double, so D equals the naive sums bit for bit.
TEST(RecurrenceMatrix, ExactDataGiveTheNaiveDistancesBitForBit) {
  const int frames = 100;
  const std::size_t cells = 1100;  // 100 x 100 x 1100 > 1e7: the tile loops run in parallel
  ScalarSeries s;
  s.frames = frames;
  for (std::size_t c = 0; c < cells; ++c) s.weights.push_back(double((c % 3 + 1) * (c % 3 + 1)));  // 1, 4, 9
  std::vector<float> values(std::size_t(frames) * cells);  // frame-major, in [-1, 1]
  for (std::size_t k = 0; k < values.size(); ++k) {
    const std::size_t frame = k / cells, c = k % cells;
    values[k] = float(int((7 * frame + 3 * c + frame * c) % 9) - 4) * 0.25f;
  }
  auto value = [&](int frame, std::size_t c) { return values[std::size_t(frame) * cells + c]; };
  s.fetch = [&](int frame, float* out) {
    for (std::size_t c = 0; c < cells; ++c) out[c] = value(frame, c);
  };
  for (RecurrenceNorm norm : {RecurrenceNorm::L2, RecurrenceNorm::L1, RecurrenceNorm::Max}) {
    Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(frames, frames);
    for (int i = 0; i < frames; ++i)
      for (int j = 0; j < frames; ++j)
        for (std::size_t c = 0; c < cells; ++c) {
          const double diff = double(value(i, c)) - double(value(j, c));
          if (norm == RecurrenceNorm::L2) expected(i, j) += s.weights[c] * diff * diff;
          else if (norm == RecurrenceNorm::L1) expected(i, j) += s.weights[c] * std::abs(diff);
          else expected(i, j) = std::max(expected(i, j), std::abs(diff));
        }
    for (GramPrecision gram : {GramPrecision::Double, GramPrecision::FloatChunked}) {
      if (norm != RecurrenceNorm::L2 && gram != GramPrecision::Double) continue;  // Gram form only
      const bool doubles = norm == RecurrenceNorm::L2 && gram == GramPrecision::Double;
      // One block, or blocks of 15 double (30 float) frames.
      for (std::int64_t budget : {std::int64_t(1) << 30, std::int64_t(cells * 4 * 2 * 30)})
        for (int tile : {1, 7, 16}) {
          int blocks = 0;
          std::int64_t clamped = -1;
          const Eigen::MatrixXd D = distanceMatrix(s, norm, budget, tile, &blocks, &clamped, gram);
          EXPECT_TRUE(D == expected) << toString(norm) << " budget " << budget << " tile " << tile;
          EXPECT_EQ(blocks, budget == std::int64_t(1) << 30 ? 1 : doubles ? 7 : 4);
          EXPECT_EQ(clamped, 0);
        }
    }
  }
}

TEST(RecurrenceMatrix, VelocityComponentField) {
  auto db = wavyDb(20);
  for (const char* field : {"u_p.y", "u_g.z"}) {
    const Eigen::MatrixXd expected = naiveR(naiveDistances(*db, field, RecurrenceNorm::L2));
    RecurrenceOptions o;
    o.field = field;
    const RecurrenceMatrix m = computeRecurrenceMatrix(*db, o);
    EXPECT_EQ(m.field, field);
    EXPECT_LT((m.R.cast<double>() - expected).cwiseAbs().maxCoeff(), 1e-6) << field;
  }
  EXPECT_THROW(parseFieldComponent("u_p.w"), InputError);
  EXPECT_THROW(parseFieldComponent("alpha_g"), InputError);
  EXPECT_THROW(parseRecurrenceNorm("l3"), InputError);
}

// A field periodic with period T frames: R = 1 on the diagonals at lags kT and the summary finds T.
TEST(RecurrenceMatrix, PeriodicFieldHasDiagonalsAtThePeriod) {
  const CartesianGrid g = smallGrid(6, 4, 3);
  const int period = 20, frames = 200;
  auto db = makeAnalyticDatabase(g, variedFluid(g), 0.005, frames, [&](int n, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < g.cellCount(); ++c)
      f.alpha_p[std::size_t(c)] = float(0.3 + 0.2 * std::sin(2.0 * M_PI * n / period + 0.3 * double(c)));
  });
  const RecurrenceMatrix m = computeRecurrenceMatrix(*db);
  const RecurrenceSummary s = summariseRecurrence(m.R);
  EXPECT_GT(s.diagonalMeans[period], 0.9999);
  EXPECT_GT(s.diagonalMeans[2 * period], 0.9999);
  EXPECT_LT(s.diagonalMeans[period / 2], 0.1);
  ASSERT_FALSE(s.strongestLags.empty());
  for (const auto& lag : s.strongestLags) EXPECT_EQ(lag.lag % period, 0) << "lag " << lag.lag;
  bool hasPeriod = false;
  for (const auto& lag : s.strongestLags) hasPeriod |= lag.lag == period;
  EXPECT_TRUE(hasPeriod);
  // Each row's largest off-diagonal values sit at i +- kT.
  for (int i = 0; i < frames; i += 17) {
    for (int j = 0; j < frames; ++j) {
      if ((j - i) % period == 0) EXPECT_GT(m.R(i, j), 0.9999f);
    }
  }
}

TEST(RecurrenceMatrix, IdenticalFramesGiveAllOnes) {
  const CartesianGrid g = smallGrid();
  auto db = makeAnalyticDatabase(g, variedFluid(g), 0.01, 5, [](int, double, FieldFrame& f) {
    std::fill(f.alpha_p.begin(), f.alpha_p.end(), 0.4f);
  });
  const RecurrenceMatrix m = computeRecurrenceMatrix(*db);
  EXPECT_EQ(m.normalisation, 0.0);
  EXPECT_TRUE((m.R.array() == 1.0f).all());
}

TEST(RecurrenceMatrix, StoredInTheDatabaseAndLoadedBack) {
  const CartesianGrid g = smallGrid();
  const std::string path = writeWavyDatabase("store.h5", g, 9);
  RecurrenceMatrix m;
  {
    auto db = FieldDatabase::open(path);
    RecurrenceOptions o;
    o.norm = RecurrenceNorm::L1;
    m = computeRecurrenceMatrix(*db, o);
  }
  storeRecurrenceMatrix(path, m);
  storeRecurrenceMatrix(path, m);  // replacing an earlier matrix works
  const auto loaded = loadRecurrenceMatrix(path, 9);
  ASSERT_TRUE(loaded.has_value());
  EXPECT_EQ(loaded->R, m.R);
  EXPECT_EQ(loaded->norm, RecurrenceNorm::L1);
  EXPECT_EQ(loaded->field, "alpha_p");
  EXPECT_DOUBLE_EQ(loaded->normalisation, m.normalisation);
  EXPECT_FALSE(loadRecurrenceMatrix(path, 10).has_value());
  EXPECT_EQ(FieldDatabase::open(path)->frameCount(), 9);  // the database still opens
}

TEST(RecurrenceMatrix, NaNInACachedFrameIsAnInputErrorNotACrash) {
  RawSpec spec;
  spec.frames = 6;
  spec.nanFrame = 4;
  const std::string path = tempPath("nan-matrix.h5");
  writeRawDatabase(path, spec);
  auto db = FieldDatabase::open(path, FrameStorage{std::int64_t(1) << 20});
  RecurrenceOptions o;
  o.field = "u_p.x";
  EXPECT_NE(expectInputError([&] { computeRecurrenceMatrix(*db, o); }, "/frames/u_p"), "NO EXCEPTION");
}

TEST(RecurrencePlot, DownsamplesByBlockMeans) {
  Eigen::MatrixXf R(1000, 1000);
  for (int j = 0; j < 1000; ++j)
    for (int i = 0; i < 1000; ++i) R(i, j) = float((i + j) % 7) / 7.0f;
  int factor = 0;
  const Eigen::MatrixXd cells = downsampleRecurrence(R, 400, &factor);
  EXPECT_EQ(factor, 3);
  EXPECT_EQ(cells.rows(), 334);
  double mean = 0.0;
  for (int j = 3; j < 6; ++j)
    for (int i = 6; i < 9; ++i) mean += R(i, j) / 9.0;
  EXPECT_NEAR(cells(2, 1), mean, 1e-12);
  EXPECT_NEAR(cells(333, 333), R(999, 999), 1e-12);  // the last, partial block holds one frame
  const std::string svg = recurrencePlot(R, 0.005, "test").str();
  EXPECT_NE(svg.find("<image"), std::string::npos);
  EXPECT_LT(svg.size(), 1u << 20);
}

// The same matrix whether the frames come from RAM or through a small LRU cache.
TEST(RecurrenceMatrix, FrameCacheGivesTheSameMatrixAsRam) {
  const CartesianGrid g = smallGrid(6, 5, 4);
  const std::string path = writeWavyDatabase("cache-matrix.h5", g, 25);
  auto ram = FieldDatabase::open(path);
  auto cached = FieldDatabase::open(path, FrameStorage{4 * ram->frameBytes()});
  RecurrenceOptions o;
  o.memoryBudgetBytes = 4000;  // several blocks: frames are fetched more than once
  o.tileFrames = 3;
  const RecurrenceMatrix a = computeRecurrenceMatrix(*ram, o), b = computeRecurrenceMatrix(*cached, o);
  EXPECT_EQ(a.R, b.R);
  EXPECT_GT(cached->cacheStats().misses, 25);  // blocks re-read frames evicted from the 4-frame cache
}

TEST(RecurrenceMatrix, AStopRequestEndsItBetweenTilesForEveryNormAndPrecision) {
  // A long database's matrix takes minutes: a cancelled job must not wait for it. The request is
  // polled once per frame loaded and then per tile (and per cell chunk of a float tile); the first
  // true answer ends the computation with rcfd::Cancelled after the parallel loop it came in.
  const int frames = 200;
  auto db = wavyDb(frames);
  for (const auto& [norm, gram] : {std::pair{RecurrenceNorm::L2, GramPrecision::Double},
                                   std::pair{RecurrenceNorm::L2, GramPrecision::Auto},
                                   std::pair{RecurrenceNorm::L1, GramPrecision::Double}}) {
    std::atomic<int> polls{0};
    RecurrenceOptions o;
    o.norm = norm;
    o.gram = gram;
    o.tileFrames = 8;  // 325 tile pairs
    o.stopRequested = [&] { return ++polls > frames + 5; };  // every frame loaded, then a few tiles
    EXPECT_THROW(computeRecurrenceMatrix(*db, o), Cancelled) << toString(norm);
    // Once seen, the request is not asked again: at most one more poll per thread already past it.
    EXPECT_LE(polls.load(), frames + 6 + omp_get_max_threads()) << toString(norm);
    // Without a request the same options give the whole matrix.
    o.stopRequested = [] { return false; };
    EXPECT_EQ(computeRecurrenceMatrix(*db, o).R.rows(), frames) << toString(norm);
  }
}

TEST(RecurrenceMatrix, ProgressRisesToOneThroughFramesAndTilesForEveryNormAndBlocking) {
  // The calibration and spray jobs' "recurrence" phase moves by this: called from the threads that
  // load frames and finish tiles, never backwards, 1 at the end, including blocked computations that
  // load frames more than once.
  const int frames = 60;
  auto db = wavyDb(frames);
  for (const auto& [norm, budget] : {std::pair{RecurrenceNorm::L2, std::int64_t(1) << 30},
                                     std::pair{RecurrenceNorm::L2, std::int64_t(4000)},
                                     std::pair{RecurrenceNorm::L1, std::int64_t(4000)}}) {
    std::mutex m;
    std::vector<double> seen;
    RecurrenceOptions o;
    o.norm = norm;
    o.gram = GramPrecision::Double;
    o.memoryBudgetBytes = budget;
    o.tileFrames = 4;
    o.progress = [&](double f) {
      std::lock_guard lock(m);
      seen.push_back(f);
    };
    const RecurrenceMatrix r = computeRecurrenceMatrix(*db, o);
    ASSERT_EQ(r.R.rows(), frames);
    ASSERT_FALSE(seen.empty()) << toString(norm);
    // Reports from several threads may arrive out of order by a unit; the largest is the end.
    EXPECT_DOUBLE_EQ(*std::max_element(seen.begin(), seen.end()), 1.0) << toString(norm) << " " << budget;
    for (double f : seen) EXPECT_TRUE(f > 0.0 && f <= 1.0) << f;
    // Many steps on the way: every frame and tile pair moves it.
    EXPECT_GT(seen.size(), std::size_t(frames)) << toString(norm);
    // The frames' loads are a small part: the fraction after the first `frames` calls is well below 1.
    std::vector<double> sorted = seen;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_LT(sorted[std::size_t(frames) - 1], 0.9) << toString(norm) << " " << budget;
  }
}
