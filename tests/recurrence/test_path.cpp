// Recurrence paths: the paper's rule on periodic fields, seeding, bounds, the Markov variant, file paths
// and path statistics.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>

#include "../fields/FieldTestUtil.hpp"
#include "recurrence/PathFile.hpp"
#include "recurrence/PathRandom.hpp"
#include "recurrence/RecurrenceMatrix.hpp"
#include "recurrence/RecurrencePath.hpp"
#include "../SanitizedBuild.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {

// R of a field periodic with `period` frames (period may be fractional).
Eigen::MatrixXf periodicR(double period, int frames) {
  const CartesianGrid g = smallGrid(5, 4, 2);
  auto db = makeAnalyticDatabase(g, variedFluid(g), 0.005, frames, [&](int n, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < g.cellCount(); ++c)
      f.alpha_p[std::size_t(c)] = float(0.3 + 0.2 * std::sin(2.0 * M_PI * n / period + 0.4 * double(c)));
  });
  return computeRecurrenceMatrix(*db).R;
}

// Circular distance of two phases measured in frames.
double phaseGap(double a, double b, double period) {
  const double d = std::fmod(std::abs(a - b), period);
  return std::min(d, period - d);
}

Eigen::MatrixXf randomishR(int n) {
  Eigen::MatrixXf R(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) R(i, j) = i == j ? 1.0f : float(0.5 + 0.45 * std::sin(0.3 * i + 0.7 * j) * std::cos(0.7 * i + 0.3 * j));
  return R;
}

void expectInRange(const RecurrencePath& p, int n) {
  for (std::size_t s = 0; s < p.frames.size(); ++s) {
    ASSERT_GE(p.frames[s], 0) << "step " << s;
    ASSERT_LT(p.frames[s], n) << "step " << s;
  }
}

// Symmetric, unit diagonal, every entry a multiple of 1/16: exact in float and free of libm, so a path
// drawn on it is the same on every platform.
Eigen::MatrixXf dyadicR(int n) {
  Eigen::MatrixXf R(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) R(i, j) = i == j ? 1.0f : float((7 * (i + j) + 3 * i * j) % 17) / 16.0f;
  return R;
}

// FNV-1a over the frame indices: pins a whole path in one number.
std::uint64_t pathHash(const RecurrencePath& p) {
  std::uint64_t h = 14695981039346656037ull;
  for (int f : p.frames) {
    h ^= std::uint64_t(std::uint32_t(f));
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace

TEST(PaperPath, JumpsLandOnTheSamePhaseOfAPeriodicField) {
  for (double period : {20.0, 12.5}) {
    const int n = 200;
    const Eigen::MatrixXf R = periodicR(period, n);
    PathSpec spec;
    const auto gen = PathGeneratorRegistry::create("paper", spec);
    const RecurrencePath p = gen->generate(R, 20000, 3);
    expectInRange(p, n);
    std::int64_t jumps = 0;
    for (std::int64_t s = 1; s < std::int64_t(p.frames.size()); ++s) {
      if (!p.isJump(s)) continue;
      ++jumps;
      const int from = p.frames[std::size_t(s - 1)], to = p.frames[std::size_t(s)];
      // The frame after the state left and the frame landed on have the same phase (within a frame).
      EXPECT_LE(phaseGap(from + 1, to, period), 1.0) << "period " << period << " jump " << from << " -> " << to;
      // The matched state (to - 1) lies in the other half.
      EXPECT_EQ(from < n / 2, to - 1 >= n / 2) << from << " -> " << to;
    }
    EXPECT_GT(jumps, 100);
    EXPECT_EQ(jumps, p.jumpCount());
    if (period == 20.0) {
      EXPECT_GT(pathStatistics(p, R).meanJumpSimilarity, 0.999);
    }
  }
}

TEST(PaperPath, SequenceLengthsFollowTheFractions) {
  const int n = 200;
  const Eigen::MatrixXf R = randomishR(n);
  PathSpec spec;  // N/20 = 10 .. N/5 = 40
  const RecurrencePath p = PathGeneratorRegistry::create("paper", spec)->generate(R, 50000, 9);
  expectInRange(p, n);
  std::vector<std::int64_t> starts{0};
  for (std::int64_t s = 1; s < std::int64_t(p.frames.size()); ++s)
    if (p.isJump(s)) starts.push_back(s);
  starts.push_back(std::int64_t(p.frames.size()));
  for (std::size_t k = 0; k + 2 < starts.size(); ++k) {  // the last sequence is cut by the step count
    const std::int64_t length = starts[k + 1] - starts[k];
    const int last = p.frames[std::size_t(starts[k + 1] - 1)];
    EXPECT_LE(length, 40);
    if (last != n - 1) {
      EXPECT_GE(length, 10);  // only a sequence that hits the last frame ends early
    }
  }
  const PathStatistics st = pathStatistics(p, R);
  EXPECT_GT(st.meanSequenceLength, 10.0);
  EXPECT_LT(st.meanSequenceLength, 40.0);
}

TEST(PaperPath, SameSeedSamePathDifferentSeedDifferentPath) {
  const Eigen::MatrixXf R = randomishR(150);
  PathSpec spec;
  const auto gen = PathGeneratorRegistry::create("paper", spec);
  const auto a = gen->generate(R, 10000, 42), b = gen->generate(R, 10000, 42), c = gen->generate(R, 10000, 43);
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_NE(a.frames, c.frames);
}

// The integer mapping uses only integer arithmetic on std::mt19937_64, whose output the C++ standard
// fixes (its 10000th value is 9981545732273789042), so these values hold on every platform. Reference:
// this implementation (recorded once; a change here changes every seeded path).
TEST(PaperPath, GoldenValuesOfTheRandomMapping) {
  std::mt19937_64 standard;
  standard.discard(9999);
  EXPECT_EQ(standard(), 9981545732273789042ull);
  std::mt19937_64 rng(1);
  std::vector<std::int64_t> draws;
  for (int k = 0; k < 6; ++k) draws.push_back(path_random::uniformInt(rng, 10, 40));
  // 64-bit mt19937 seeded with 1 yields 2469588189546311528, ... ; x % 31 + 10 for each.
  std::mt19937_64 check(1);
  for (int k = 0; k < 6; ++k) EXPECT_EQ(draws[std::size_t(k)], 10 + std::int64_t(check() % 31));
  EXPECT_EQ(draws[0], 10 + std::int64_t(2469588189546311528ull % 31));
}

// The paths of fixed seeds, recorded once from this implementation: the first frames and a hash of
// 5000 steps. Platform-independent (integer draws, PathRandom.hpp; R exact, dyadicR); a change here
// changes every seeded run.
TEST(SeededPaths, FixedSeedsGiveRecordedPaths) {
  struct Case {
    const char* type;
    int frames;
    double minFraction, maxFraction;
    int minSequenceFrames, window;
    bool identity;  // R = I: the Markov rule's uniform fallback
    std::uint64_t seed;
    std::vector<int> prefix;
    std::uint64_t hash;
  };
  const std::vector<Case> cases{
      {"paper", 60, 0.05, 0.2, 1, 0, false, 42,
       {11, 12, 13, 14, 15, 16, 17, 47, 48, 49, 14, 15, 16, 17, 18, 41, 42, 43, 44, 17,
        18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 34, 35, 36, 37, 38, 39, 40, 41, 42, 3},
       1353250851929529080ull},
      // Sequences as long as the database: every one ends at the last frame (forced jump).
      {"paper", 7, 0.9, 1.0, 1, 0, false, 5,
       {4, 5, 6, 2, 3, 4, 5, 6, 2, 3, 4, 5, 6, 2, 3, 4, 5, 6, 2, 3},
       2187295881536834069ull},
      {"markov", 60, 0.05, 0.2, 3, 5, false, 77,
       {41, 42, 43, 44, 45, 30, 31, 32, 33, 34, 35, 36, 37, 38, 39, 40, 41, 42, 43, 44,
        34, 35, 36, 37, 38, 39, 40, 41, 42, 43, 44, 45, 46, 47, 48, 49, 50, 51, 52, 53},
       18022685333015640347ull},
      {"markov", 30, 0.05, 0.2, 1, 2, true, 3,
       {14, 15, 16, 17, 18, 19, 1, 2, 3, 4, 5, 6, 22, 23, 24, 18, 19, 20, 21, 22,
        23, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27, 7, 8, 25, 15, 16, 17, 18, 19, 24},
       7912976070391007322ull},
  };
  for (const Case& c : cases) {
    PathSpec spec;
    spec.min_sequence_fraction = c.minFraction;
    spec.max_sequence_fraction = c.maxFraction;
    spec.min_sequence_frames = c.minSequenceFrames;
    spec.correlation_window = c.window;
    const Eigen::MatrixXf R =
        c.identity ? Eigen::MatrixXf(Eigen::MatrixXf::Identity(c.frames, c.frames)) : dyadicR(c.frames);
    const RecurrencePath p = PathGeneratorRegistry::create(c.type, spec)->generate(R, 5000, c.seed);
    ASSERT_EQ(p.frames.size(), 5000u);
    EXPECT_EQ(std::vector<int>(p.frames.begin(), p.frames.begin() + std::ptrdiff_t(c.prefix.size())), c.prefix)
        << c.type << " seed " << c.seed;
    EXPECT_EQ(pathHash(p), c.hash) << c.type << " seed " << c.seed;
  }
}

TEST(PaperPath, NeverRunsPastTheLastFrame) {
  // Sequences as long as the database force jumps at the end.
  for (int n : {3, 4, 7, 50}) {
    PathSpec spec;
    spec.min_sequence_fraction = 0.9;
    spec.max_sequence_fraction = 1.0;
    const RecurrencePath p = PathGeneratorRegistry::create("paper", spec)->generate(randomishR(n), 5000, 5);
    expectInRange(p, n);
  }
}

TEST(PaperPath, Generates720000StepsWellUnderASecond) {
  const Eigen::MatrixXf R = randomishR(2000);
  PathSpec spec;
  for (const char* type : {"paper", "markov"}) {
    const auto start = std::chrono::steady_clock::now();
    const RecurrencePath p = PathGeneratorRegistry::create(type, spec)->generate(R, 720000, 1);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(p.frames.size(), 720000u);
    if (!rcfd::test::kSanitizedBuild) {
      EXPECT_LT(seconds, 0.5) << type;
    }
    expectInRange(p, 2000);
  }
}

TEST(PaperPath, RefusesBadSettings) {
  PathSpec spec;
  spec.min_sequence_fraction = 0.0;
  EXPECT_NE(expectInputError([&] { PathGeneratorRegistry::create("paper", spec); }, "/rcfd/path/min_sequence_fraction"),
            "NO EXCEPTION");
  spec = PathSpec{};
  spec.max_sequence_fraction = 0.01;
  EXPECT_NE(expectInputError([&] { PathGeneratorRegistry::create("paper", spec); }, "/rcfd/path/max_sequence_fraction"),
            "NO EXCEPTION");
  const auto gen = PathGeneratorRegistry::create("paper", PathSpec{});
  EXPECT_NE(expectInputError([&] { gen->generate(Eigen::MatrixXf::Ones(2, 2), 10, 1); }, "/recurrence/matrix"),
            "NO EXCEPTION");
  EXPECT_THROW(PathGeneratorRegistry::create("zigzag", PathSpec{}), std::out_of_range);
}

TEST(MarkovPath, SeededInRangeAndJumpsLeaveTheWindow) {
  const int n = 300;
  const Eigen::MatrixXf R = randomishR(n);
  PathSpec spec;
  spec.min_sequence_frames = 8;
  spec.correlation_window = 25;
  const auto gen = PathGeneratorRegistry::create("markov", spec);
  const RecurrencePath a = gen->generate(R, 60000, 77), b = gen->generate(R, 60000, 77);
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_NE(a.frames, gen->generate(R, 60000, 78).frames);
  expectInRange(a, n);
  std::int64_t last = 0, sequences = 0, total = 0;
  for (std::int64_t s = 1; s < std::int64_t(a.frames.size()); ++s) {
    if (!a.isJump(s)) continue;
    const int from = a.frames[std::size_t(s - 1)], matched = a.frames[std::size_t(s)] - 1;
    EXPECT_GT(std::abs(matched - from), 25) << "jump " << from << " -> " << matched + 1;
    const std::int64_t length = s - last;
    if (from != n - 1 && last > 0) {
      EXPECT_GE(length, 8);
      total += length;
      ++sequences;
    }
    last = s;
  }
  // Mean length N (0.05 + 0.2) / 2 = 37.5 frames (sequences cut by the last frame excluded: a bit less).
  ASSERT_GT(sequences, 500);
  const double mean = double(total) / double(sequences);
  EXPECT_GT(mean, 30.0);
  EXPECT_LT(mean, 40.0);
}

TEST(MarkovPath, JumpTargetsFavourSimilarStates) {
  // Two families of states: R is high within a family, zero across. Jumps stay in the family.
  const int n = 100;
  Eigen::MatrixXf R(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) R(i, j) = (i / 10) % 2 == (j / 10) % 2 ? 1.0f : 0.0f;
  PathSpec spec;
  spec.min_sequence_frames = 1;
  spec.correlation_window = 0;
  spec.min_sequence_fraction = spec.max_sequence_fraction = 0.01;  // mean length 1: jump every step
  const RecurrencePath p = PathGeneratorRegistry::create("markov", spec)->generate(R, 5000, 2);
  for (std::int64_t s = 1; s < std::int64_t(p.frames.size()); ++s) {
    if (!p.isJump(s)) continue;
    const int from = p.frames[std::size_t(s - 1)], matched = p.frames[std::size_t(s)] - 1;
    ASSERT_EQ((from / 10) % 2, (matched / 10) % 2) << from << " -> " << matched;
  }
}

TEST(MarkovPath, WindowExcludingEverythingIsRefused) {
  PathSpec spec;
  spec.correlation_window = 60;
  const auto gen = PathGeneratorRegistry::create("markov", spec);
  EXPECT_NE(expectInputError([&] { gen->generate(randomishR(100), 100, 1); }, "/rcfd/path/correlation_window"),
            "NO EXCEPTION");
  spec.correlation_window = -1;
  EXPECT_NE(expectInputError([&] { PathGeneratorRegistry::create("markov", spec); }, "/rcfd/path/correlation_window"),
            "NO EXCEPTION");
}

TEST(FilePath, ReadsTextAndHdf5PathsAndChecksThem) {
  RecurrencePath fixed;
  for (int s = 0; s < 100; ++s) fixed.frames.push_back((s * 7) % 30);
  for (const char* name : {"path.txt", "path.h5"}) {
    PathSpec spec;
    spec.type = "file";
    spec.file = tempPath(name);
    writePathFile(spec.file, fixed);
    const auto gen = PathGeneratorRegistry::create("file", spec);
    EXPECT_EQ(gen->generate(randomishR(30), 100, 1).frames, fixed.frames) << name;
    EXPECT_EQ(gen->generate(randomishR(30), 40, 9).frames,
              std::vector<int>(fixed.frames.begin(), fixed.frames.begin() + 40));
    EXPECT_NE(expectInputError([&] { gen->generate(randomishR(30), 101, 1); }, "/rcfd/path/file"), "NO EXCEPTION");
    EXPECT_NE(expectInputError([&] { gen->generate(randomishR(20), 100, 1); }, "/rcfd/path/file").find("entry"),
              std::string::npos);
  }
  PathSpec spec;
  spec.file = tempPath("bad.txt");
  std::ofstream(spec.file) << "# comment\n0 1 2\n3 four 5\n";
  EXPECT_NE(expectInputError([&] { PathGeneratorRegistry::create("file", spec); }, "line 3"), "NO EXCEPTION");
  spec.file.clear();
  EXPECT_NE(expectInputError([&] { PathGeneratorRegistry::create("file", spec); }, "/rcfd/path/file"), "NO EXCEPTION");
}

TEST(PathStatistics, CountsJumpsAndMeanSimilarity) {
  Eigen::MatrixXf R = randomishR(10);
  RecurrencePath p;
  p.frames = {0, 1, 2, 7, 8, 3};  // jumps at steps 3 (2 -> 7) and 5 (8 -> 3)
  const PathStatistics st = pathStatistics(p, R);
  EXPECT_EQ(st.jumps, 2);
  EXPECT_NEAR(st.meanJumpSimilarity, (double(R(2, 6)) + double(R(8, 2))) / 2.0, 1e-12);
  EXPECT_DOUBLE_EQ(st.meanSequenceLength, 2.0);
  p.frames.push_back(10);
  EXPECT_THROW(pathStatistics(p, R), std::out_of_range);
}
