// rcfd-bench recurrence: the recurrence matrix of Eq. (6)-(7) at the paper's size, 2000 frames x 73,647
// cells (--quick: 200 frames), synthetic pseudo-periodic alpha_P held in RAM as float32 like a loaded
// database. Headline: "matrix_seconds" (L2, double Gram form). Also: a spot check of 200 entries against
// a naive double loop, the same matrix by float32 GEMM (to justify double accumulation), and the L1
// norm's direct loop on a subset.

#include <Eigen/Core>
#include <chrono>
#include <iostream>
#include <random>

#include "BenchRegistry.hpp"
#include "SyntheticFields.hpp"
#include "recurrence/RecurrenceMatrix.hpp"
#include "recurrence/RecurrencePath.hpp"

namespace rcfd::bench {
namespace {

double since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

nlohmann::json run(const Options& options) {
  const int frames = options.quick ? 200 : 2000;
  const CartesianGrid grid = paperSizeGrid();
  const std::vector<float> fluid = paperSizeFluid(grid);
  const std::int64_t cells = grid.cellCount();
  std::cout << "recurrence matrix: " << frames << " frames x " << cells << " cells (synthetic alpha_P)\n";

  auto t0 = std::chrono::steady_clock::now();
  std::vector<float> store(std::size_t(frames * cells));
#pragma omp parallel for schedule(dynamic, 4)
  for (int n = 0; n < frames; ++n) syntheticAlpha(grid, n, store.data() + std::size_t(n) * std::size_t(cells));
  std::cout << "  generated the frames in " << since(t0) << " s\n";

  ScalarSeries series;
  series.frames = frames;
  for (std::int64_t c = 0; c < cells; ++c) series.weights.push_back(double(fluid[std::size_t(c)]) * grid.cellVolume());
  series.fetch = [&](int n, float* out) {
    std::copy_n(store.data() + std::size_t(n) * std::size_t(cells), cells, out);
  };

  RecurrenceOptions ro;
  const RecurrenceMatrix m = computeRecurrenceMatrix(series, ro);
  std::cout << "  L2 (double Gram, " << m.frameBlocks << " block): " << m.seconds << " s, mean R "
            << (m.R.sum() - frames) / (double(frames) * (frames - 1)) << ", clamped " << m.clampedNegatives << "\n";

  // Spot check against a naive double loop over Eq. (6).
  std::mt19937_64 rng(5);
  double maxError = 0.0;
  for (int k = 0; k < 200; ++k) {
    const int i = int(rng() % std::uint64_t(frames)), j = int(rng() % std::uint64_t(frames));
    const float* a = store.data() + std::size_t(i) * std::size_t(cells);
    const float* b = store.data() + std::size_t(j) * std::size_t(cells);
    double d = 0.0;
    for (std::int64_t c = 0; c < cells; ++c) {
      const double diff = double(a[c]) - double(b[c]);
      d += series.weights[std::size_t(c)] * diff * diff;
    }
    maxError = std::max(maxError, std::abs(double(m.R(i, j)) - (1.0 - d / m.normalisation)));
  }
  std::cout << "  max |R - naive| over 200 entries: " << maxError << "\n";

  // Float GEMM over chunks of 2048 cells summed in double (GramPrecision::FloatChunked).
  RecurrenceOptions fc;
  fc.gram = GramPrecision::FloatChunked;
  const RecurrenceMatrix mc = computeRecurrenceMatrix(series, fc);
  const double chunkedError = (mc.R - m.R).cwiseAbs().maxCoeff();
  std::cout << "  float GEMM, chunks summed in double: " << mc.seconds << " s, max |R - R_double| = "
            << chunkedError << "\n";

  // A plain float32 Gram matrix over all cells at once (one SGEMM, single-threaded), centred the same
  // way: the accuracy a float-only implementation would have.
  Eigen::setNbThreads(1);
  t0 = std::chrono::steady_clock::now();
  Eigen::MatrixXf X(cells, frames);
#pragma omp parallel for
  for (int n = 0; n < frames; ++n) {
    const float* a = store.data() + std::size_t(n) * std::size_t(cells);
    for (std::int64_t c = 0; c < cells; ++c)
      X(c, n) = float(std::sqrt(series.weights[std::size_t(c)]) * (double(a[c]) - double(store[std::size_t(c)])));
  }
  Eigen::MatrixXf G = X.transpose() * X;
  Eigen::VectorXf norms = G.diagonal();
  Eigen::MatrixXd D(frames, frames);
  for (int j = 0; j < frames; ++j)
    for (int i = 0; i < frames; ++i) D(i, j) = std::max(0.0, double(norms[i]) + norms[j] - 2.0 * G(i, j));
  const double floatSeconds = since(t0);
  const RecurrenceMatrix mf = normaliseDistances(D);
  const double floatError = (mf.R - m.R).cwiseAbs().maxCoeff();
  Eigen::setNbThreads(0);
  std::cout << "  plain float32 GEMM (1 thread): " << floatSeconds << " s, max |R_float - R_double| = " << floatError << "\n";
  X.resize(0, 0);

  // The paper's path for one hour at dt = 5 ms (720,000 steps) from this matrix.
  double pathSeconds[2] = {0.0, 0.0};
  const char* pathTypes[2] = {"paper", "markov"};
  for (int k = 0; k < 2; ++k) {
    const auto generator = PathGeneratorRegistry::create(pathTypes[k], PathSpec{});
    t0 = std::chrono::steady_clock::now();
    const RecurrencePath path = generator->generate(m.R, 720000, 1);
    pathSeconds[k] = since(t0);
    const PathStatistics st = pathStatistics(path, m.R);
    std::cout << "  " << pathTypes[k] << " path, 720,000 steps: " << pathSeconds[k] << " s, " << st.jumps
              << " jumps, mean R at jumps " << st.meanJumpSimilarity << "\n";
  }

  // L1 direct loop on a subset (it scales with N^2).
  const int subset = std::min(frames, 400);
  ScalarSeries sub = series;
  sub.frames = subset;
  RecurrenceOptions l1;
  l1.norm = RecurrenceNorm::L1;
  const RecurrenceMatrix ml1 = computeRecurrenceMatrix(sub, l1);
  std::cout << "  L1 direct loop on " << subset << " frames: " << ml1.seconds << " s (x"
            << double(frames) * frames / (double(subset) * subset) << " for all frames)\n";

  return {{"matrix_seconds", m.seconds},
          {"frames", frames},
          {"cells", cells},
          {"frame_blocks", m.frameBlocks},
          {"clamped_negatives", m.clampedNegatives},
          {"spot_check_max_abs_error", maxError},
          {"float_chunked_seconds", mc.seconds},
          {"float_chunked_max_abs_error", chunkedError},
          {"float_gemm_seconds", floatSeconds},
          {"float_gemm_max_abs_error", floatError},
          {"paper_path_720000_seconds", pathSeconds[0]},
          {"markov_path_720000_seconds", pathSeconds[1]},
          {"l1_frames", subset},
          {"l1_seconds", ml1.seconds}};
}

const bool registered = addBenchmark("recurrence", "recurrence matrix, 2000 frames x 73,647 cells (Eq. 6-7)", run);

}  // namespace
}  // namespace rcfd::bench
