// field_average: time-averaged alpha_P of the tracers and of the recurrence fields per cell (the
// paper's Fig. 9), and their volume-weighted RMS difference.
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
#pragma omp parallel for schedule(static) if (cells > kParallelThreshold)
    for (std::int64_t c = 0; c < cells; ++c) {
      tracerSum_[std::size_t(c)] += ctx.tracerAlpha[std::size_t(c)];
      recurrenceSum_[std::size_t(c)] += sampler.alphaP(c);
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
    summary["field_average"] = {{"samples", samples_},
                                {"rms_difference", volume > 0.0 ? std::sqrt(diff2 / volume) : 0.0}};
  }

  void saveState(h5::File& f, const std::string& g) const override {
    f.write(g + "/tracer_sum", tracerSum_);
    f.write(g + "/recurrence_sum", recurrenceSum_);
    f.write(g + "/samples", std::vector<std::int64_t>{samples_});
  }
  void loadState(const h5::File& f, const std::string& g) override {
    tracerSum_ = f.readDoubles(g + "/tracer_sum");
    recurrenceSum_ = f.readDoubles(g + "/recurrence_sum");
    samples_ = f.readInt64s(g + "/samples").at(0);
  }

 private:
  std::vector<double> tracerSum_, recurrenceSum_;
  std::int64_t samples_ = 0;
};

const bool registered = TracerEffectRegistry::add(
    "field_average", {"tracer_volume_fraction"}, 40,
    "time-averaged alpha_P of tracers vs recurrence fields per cell (Fig. 9)",
    [](TracerContext& c) { return std::make_unique<FieldAverageEffect>(c); });

}  // namespace
}  // namespace rcfd
