// field_average: time-averaged alpha_P of the tracers and of the recurrence fields per cell (the
// paper's Fig. 9), and their volume-weighted RMS difference. Also the instantaneous RMS difference over
// all open cells and steps beside its counting floor: tracers placed independently with the density
// alpha_P^rec would put Poisson(alpha_P^rec / a_c) tracers into cell c (a_c the alpha_P of one tracer
// there), an RMS of sqrt(a_c alpha_P^rec) that no tracer model can beat. The ratio of the two is how
// much over- and under-packing the motion adds, whatever the tracer count (docs/calibration.md).
#include <algorithm>
#include <cmath>
#include <memory>

#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace {

class FieldAverageEffect final : public TracerEffect {
 public:
  explicit FieldAverageEffect(TracerContext& ctx)
      : tracerSum_(std::size_t(ctx.grid.cellCount()), 0.0), recurrenceSum_(tracerSum_.size(), 0.0) {}

  std::size_t allocatedBytes() const override { return 2 * tracerSum_.size() * sizeof(double); }

  void afterMove(TracerContext& ctx) override {
    if (!ctx.collecting()) return;
    const FrameSampler sampler = ctx.sampler();
    const std::int64_t cells = std::int64_t(tracerSum_.size());
    const double volumePerTracer = ctx.cloud.particlesPerTracer * ctx.cloud.particleVolume;
    // Sums over fixed chunks of cells, added in chunk order: the same bits for any thread count.
    constexpr std::int64_t kChunk = 4096;
    const std::int64_t chunks = (cells + kChunk - 1) / kChunk;
    chunkSums_.assign(2 * std::size_t(chunks), 0.0);
#pragma omp parallel for schedule(static) if (cells > kParallelThreshold)
    for (std::int64_t k = 0; k < chunks; ++k) {
      double squares = 0.0, floor = 0.0;
      for (std::int64_t c = k * kChunk; c < std::min(cells, (k + 1) * kChunk); ++c) {
        const double tracer = ctx.tracerAlpha[std::size_t(c)], rec = sampler.alphaP(c);
        const double open = ctx.openVolume[std::size_t(c)];
        tracerSum_[std::size_t(c)] += tracer;
        recurrenceSum_[std::size_t(c)] += rec;
        squares += open * (tracer - rec) * (tracer - rec);
        if (open > 0.0) floor += volumePerTracer * std::max(0.0, rec);  // open x a_c alpha_rec
      }
      chunkSums_[2 * std::size_t(k)] = squares, chunkSums_[2 * std::size_t(k) + 1] = floor;
    }
    for (std::int64_t k = 0; k < chunks; ++k) {
      squaresSum_ += chunkSums_[2 * std::size_t(k)], floorSum_ += chunkSums_[2 * std::size_t(k) + 1];
    }
    ++samples_;
  }

  void writeResults(const TracerContext& ctx, h5::File& out, nlohmann::json& summary) const override {
    const double n = double(std::max<std::int64_t>(samples_, 1));
    std::vector<float> tracer(tracerSum_.size()), recurrence(tracerSum_.size());
    double diff2 = 0.0, volume = 0.0;
    for (std::size_t c = 0; c < tracer.size(); ++c) {
      tracer[c] = float(tracerSum_[c] / n);
      recurrence[c] = float(recurrenceSum_[c] / n);
      const double d = double(tracer[c]) - double(recurrence[c]);
      diff2 += ctx.openVolume[c] * d * d;
      volume += ctx.openVolume[c];
    }
    const auto& s = ctx.grid.shape;
    const std::vector<hsize_t> shape{hsize_t(s[2]), hsize_t(s[1]), hsize_t(s[0])};
    out.write("/field_average/alpha_p_tracers", tracer, shape);
    out.write("/field_average/alpha_p_recurrence", recurrence, shape);
    const double perStep = volume * n;
    const double instantaneous = perStep > 0.0 ? std::sqrt(squaresSum_ / perStep) : 0.0;
    const double floor = perStep > 0.0 ? std::sqrt(floorSum_ / perStep) : 0.0;
    summary["field_average"] = {{"samples", samples_},
                                {"rms_difference", volume > 0.0 ? std::sqrt(diff2 / volume) : 0.0},
                                {"instantaneous_rms_difference", instantaneous},
                                {"counting_floor_rms", floor},
                                {"rms_over_floor", floor > 0.0 ? instantaneous / floor : 0.0}};
  }

  void saveState(h5::File& f, const std::string& g) const override {
    f.write(g + "/tracer_sum", tracerSum_);
    f.write(g + "/recurrence_sum", recurrenceSum_);
    f.write(g + "/samples", std::vector<std::int64_t>{samples_});
    f.write(g + "/instantaneous", std::vector<double>{squaresSum_, floorSum_});
  }
  void loadState(const h5::File& f, const std::string& g) override {
    tracerSum_ = f.readDoubles(g + "/tracer_sum");
    recurrenceSum_ = f.readDoubles(g + "/recurrence_sum");
    samples_ = f.readInt64s(g + "/samples").at(0);
    const auto inst = f.readDoubles(g + "/instantaneous");
    squaresSum_ = inst.at(0), floorSum_ = inst.at(1);
  }

 private:
  std::vector<double> tracerSum_, recurrenceSum_;
  std::int64_t samples_ = 0;
  double squaresSum_ = 0.0;  ///< sum over steps and cells of V_open (alpha_tracers - alpha_rec)^2 [m3]
  double floorSum_ = 0.0;    ///< sum over steps and cells of V_open a_c alpha_rec [m3]
  std::vector<double> chunkSums_;
};

const bool registered = TracerEffectRegistry::add(
    "field_average", {"tracer_volume_fraction"}, 40,
    "time-averaged alpha_P of tracers vs recurrence fields per cell (Fig. 9)",
    [](TracerContext& c) { return std::make_unique<FieldAverageEffect>(c); });

}  // namespace
}  // namespace rcfd
