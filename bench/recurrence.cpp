// rcfd-bench recurrence: the recurrence matrix of Eq. (6)-(7) at the paper's size, 2000 frames x 73,647
// cells (--quick: 200 frames), synthetic pseudo-periodic alpha_P held in RAM as float32 like a loaded
// database. Headline: "matrix_seconds" (L2, the default GramPrecision::Auto). Also: the double-GEMM
// matrix, a check of 200 entries against a naive double loop, a plain float32 GEMM (the accuracy of
// float without double accumulation), the paths for one hour, and the L1 direct loop on a subset.

#include <Eigen/Core>
#include <chrono>
#include <ctime>
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

  // The default (GramPrecision::Auto): float GEMM over 512-cell chunks summed in double, spot-checked.
  RecurrenceOptions ro;
  const std::clock_t cpu0 = std::clock();
  const RecurrenceMatrix m = computeRecurrenceMatrix(series, ro);
  const double matrixCpu = double(std::clock() - cpu0) / CLOCKS_PER_SEC;
  std::cout << "  L2 default (" << (m.gramUsed == GramPrecision::Double ? "double" : "float chunks summed in double")
            << (m.autoFellBack ? ", fell back to double" : "") << ", " << m.frameBlocks << " block): " << m.seconds
            << " s wall, " << matrixCpu << " s CPU, spot check " << m.spotCheckError << ", mean R "
            << (m.R.sum() - frames) / (double(frames) * (frames - 1)) << ", clamped " << m.clampedNegatives << "\n";

  // Double GEMM throughout (GramPrecision::Double).
  RecurrenceOptions rd;
  rd.gram = GramPrecision::Double;
  const std::clock_t cpu1 = std::clock();
  const RecurrenceMatrix md = computeRecurrenceMatrix(series, rd);
  const double doubleCpu = double(std::clock() - cpu1) / CLOCKS_PER_SEC;
  const double chunkedError = (md.R - m.R).cwiseAbs().maxCoeff();
  std::cout << "  L2 double GEMM: " << md.seconds << " s wall, " << doubleCpu << " s CPU; max |R_default - R_double| = "
            << chunkedError << "\n";

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
    maxError = std::max(maxError, std::abs(double(md.R(i, j)) - (1.0 - d / md.normalisation)));
  }
  std::cout << "  max |R_double - naive| over 200 entries: " << maxError << "\n";

  // A plain float32 Gram matrix over all cells at once (one SGEMM), centred the same way, on the first
  // 500 frames (the error grows with the cell count, not the frame count): the accuracy a float-only
  // implementation would have.
  const int plainFrames = std::min(frames, 500);
  t0 = std::chrono::steady_clock::now();
  Eigen::MatrixXf X(cells, plainFrames);
  for (int n = 0; n < plainFrames; ++n) {
    const float* a = store.data() + std::size_t(n) * std::size_t(cells);
    for (std::int64_t c = 0; c < cells; ++c)
      X(c, n) = float(std::sqrt(series.weights[std::size_t(c)]) * (double(a[c]) - double(store[std::size_t(c)])));
  }
  Eigen::setNbThreads(1);  // Eigen's own threading stalls when other processes share the cores
  const Eigen::MatrixXf G = X.transpose() * X;
  Eigen::setNbThreads(0);
  double floatError = 0.0;
  for (int j = 0; j < plainFrames; ++j)
    for (int i = 0; i < plainFrames; ++i) {
      const double d = std::max(0.0, double(G(i, i)) + G(j, j) - 2.0 * G(i, j));
      const double r = i == j ? 1.0 : 1.0 - d / md.normalisation;
      floatError = std::max(floatError, std::abs(r - double(md.R(i, j))));
    }
  const double floatSeconds = since(t0);
  std::cout << "  plain float32 GEMM on " << plainFrames << " frames: " << floatSeconds
            << " s, max |R_float - R_double| = " << floatError << "\n";
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
          {"matrix_cpu_seconds", matrixCpu},
          {"matrix_gram", m.gramUsed == GramPrecision::Double ? "double" : "float_chunked"},
          {"matrix_spot_check_error", m.spotCheckError},
          {"double_seconds", md.seconds},
          {"double_cpu_seconds", doubleCpu},
          {"default_vs_double_max_abs_error", chunkedError},
          {"frames", frames},
          {"cells", cells},
          {"frame_blocks", m.frameBlocks},
          {"clamped_negatives", m.clampedNegatives},
          {"spot_check_max_abs_error", maxError},
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
