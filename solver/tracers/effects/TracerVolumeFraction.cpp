// tracer_volume_fraction: maps the tracers to the grid at the start of every step. alpha_P of a cell is
// (tracers in the cell) x (particle volume per tracer) / (open volume of the cell). Counting is integer
// and therefore the same for any thread count.
#include <memory>

#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace {

class TracerVolumeFractionEffect final : public TracerEffect {
 public:
  explicit TracerVolumeFractionEffect(TracerContext& ctx) {
    ctx.tracerCell.assign(ctx.cloud.size(), 0);
    ctx.tracerCount.assign(std::size_t(ctx.grid.cellCount()), 0);
    ctx.tracerAlpha.assign(std::size_t(ctx.grid.cellCount()), 0.0f);
    bytes_ = ctx.tracerCell.size() * sizeof(std::int32_t) + ctx.tracerCount.size() * sizeof(std::int32_t) +
             ctx.tracerAlpha.size() * sizeof(float);
  }
  std::size_t allocatedBytes() const override { return bytes_; }

  void beforeMove(TracerContext& ctx) override {
    const auto& cloud = ctx.cloud;
    auto& count = ctx.tracerCount;
    std::fill(count.begin(), count.end(), 0);
    const std::int64_t n = std::int64_t(cloud.size());
#pragma omp parallel for schedule(static) if (n > kParallelThreshold)
    for (std::int64_t i = 0; i < n; ++i) {
      const auto c = std::int32_t(ctx.grid.flatIndexOf(cloud.position(std::size_t(i))));
      ctx.tracerCell[std::size_t(i)] = c;
#pragma omp atomic
      ++count[std::size_t(c)];
    }
    const double volumePerTracer = cloud.particlesPerTracer * cloud.particleVolume;
    const std::int64_t cells = ctx.grid.cellCount();
#pragma omp parallel for schedule(static) if (cells > kParallelThreshold)
    for (std::int64_t c = 0; c < cells; ++c) {
      const double open = ctx.openVolume[std::size_t(c)];
      ctx.tracerAlpha[std::size_t(c)] =
          open > 0.0 ? float(count[std::size_t(c)] * volumePerTracer / open) : 0.0f;
    }
  }

 private:
  std::size_t bytes_ = 0;
};

const bool registered = TracerEffectRegistry::add(
    "tracer_volume_fraction", {}, 10, "tracers mapped to the grid every step (alpha_P of the tracers)",
    [](TracerContext& c) { return std::make_unique<TracerVolumeFractionEffect>(c); });

}  // namespace
}  // namespace rcfd
