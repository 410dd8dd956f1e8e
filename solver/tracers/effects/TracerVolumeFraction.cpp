// tracer_volume_fraction: maps the tracers to the grid at the start of every step (from the cells the
// motion kernel found for the positions it wrote, when it did). alpha_P of a cell is
// (tracers in the cell) x (particle volume per tracer) / (open volume of the cell). Counting is integer
// and therefore the same for any thread count. Each thread counts its share of the tracers into its own
// histogram (no atomics: a locked increment per tracer cost more than the rest of this pass), and the
// histograms are summed per cell.
#include <algorithm>
#include <memory>
#include <omp.h>

#include "tracers/CellIndex.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace {

class TracerVolumeFractionEffect final : public TracerEffect {
 public:
  explicit TracerVolumeFractionEffect(TracerContext& ctx) {
    ctx.tracerCell.assign(ctx.cloud.size(), 0);
    ctx.nextTracerCell.assign(ctx.cloud.size(), 0);
    ctx.tracerCount.assign(std::size_t(ctx.grid.cellCount()), 0);
    ctx.tracerAlpha.assign(std::size_t(ctx.grid.cellCount()), 0.0f);
    bytes_ = 2 * ctx.tracerCell.size() * sizeof(std::int32_t) + ctx.tracerCount.size() * sizeof(std::int32_t) +
             ctx.tracerAlpha.size() * sizeof(float);
  }
  std::size_t allocatedBytes() const override {
    return bytes_ + partial_.capacity() * sizeof(std::int32_t) + alphaPerTracer_.capacity() * sizeof(double);
  }

  void beforeMove(TracerContext& ctx) override {
    const auto& cloud = ctx.cloud;
    auto& count = ctx.tracerCount;
    const std::int64_t n = std::int64_t(cloud.size());
    const std::int64_t cells = ctx.grid.cellCount();
    const bool parallel = n > kParallelThreshold;
    const int threads = parallel ? omp_get_max_threads() : 1;
    partial_.resize(std::size_t(threads - 1) * std::size_t(cells));
    if (alphaPerTracer_.empty()) {
      // alpha_P of one tracer in each cell: its particles' volume over the open volume (0 where closed).
      const double volumePerTracer = cloud.particlesPerTracer * cloud.particleVolume;
      alphaPerTracer_.resize(std::size_t(cells));
      for (std::int64_t c = 0; c < cells; ++c) {
        const double open = ctx.openVolume[std::size_t(c)];
        alphaPerTracer_[std::size_t(c)] = open > 0.0 ? volumePerTracer / open : 0.0;
      }
    }
    const bool reuse = ctx.nextTracerCellStep == ctx.step;
    if (reuse) ctx.tracerCell.swap(ctx.nextTracerCell);
    ctx.nextTracerCellStep = -1;
    // One parallel region (each is a fork and a join): cells and counts of the tracers, block by block;
    // then, after a barrier, the threads' histograms summed and alpha_P, cell by cell.
#pragma omp parallel if (parallel) num_threads(threads)
    {
      const int t = omp_get_thread_num();
      const int others = omp_get_num_threads() - 1;  // a team may be smaller than asked for
      std::int32_t* histogram = t == 0 ? count.data() : partial_.data() + std::size_t(t - 1) * std::size_t(cells);
      std::fill(histogram, histogram + cells, 0);
      // The cells of the tracers: the motion kernel's, found for the positions it has just written, or
      // (the first step, after a checkpoint, after positions were set from outside) computed here.
      const CellIndexer indexer(ctx.grid);
      const double* x = cloud.x.data();
      const double* y = cloud.y.data();
      const double* z = cloud.z.data();
      std::int32_t* cellOut = ctx.tracerCell.data();
      constexpr std::int64_t kBlock = 256;
#pragma omp for schedule(static)
      for (std::int64_t b = 0; b < (n + kBlock - 1) / kBlock; ++b) {
        const std::int64_t i0 = b * kBlock;
        const int count = int(std::min(kBlock, n - i0));
        std::int32_t* out = cellOut + i0;
        if (!reuse) indexer.cellsOf(count, x + i0, y + i0, z + i0, out);
        for (int k = 0; k < count; ++k) ++histogram[out[k]];
      }
      // (the implicit barrier of the loop above: every histogram is complete)
      std::int32_t* total = count.data();
      const double* perTracer = alphaPerTracer_.data();
      float* alpha = ctx.tracerAlpha.data();
      // Plain loops over cells, which vectorise (a loop over the threads inside them did not).
      for (int u = 0; u < others; ++u) {
        const std::int32_t* part = partial_.data() + std::size_t(u) * std::size_t(cells);
#pragma omp for simd schedule(static)
        for (std::int64_t c = 0; c < cells; ++c) total[c] += part[c];
      }
#pragma omp for simd schedule(static)
      for (std::int64_t c = 0; c < cells; ++c) alpha[c] = float(double(total[c]) * perTracer[c]);
    }
  }

 private:
  std::size_t bytes_ = 0;
  std::vector<std::int32_t> partial_;  ///< histograms of threads 1.. (thread 0 counts into tracerCount)
  std::vector<double> alphaPerTracer_; ///< per cell: alpha_P of one tracer [-]
};

const bool registered = TracerEffectRegistry::add(
    "tracer_volume_fraction", {}, 10, "tracers mapped to the grid every step (alpha_P of the tracers)",
    [](TracerContext& c) { return std::make_unique<TracerVolumeFractionEffect>(c); });

}  // namespace
}  // namespace rcfd
