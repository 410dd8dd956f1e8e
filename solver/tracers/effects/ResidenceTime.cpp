// residence_time: spray-zone holdup over time and the duration of every stay of a tracer in the spray
// zone (the paper's Figs. 10-11). Durations are counted in whole steps, so the histogram and its sums
// are integers: identical for any thread count and across checkpoint/resume. Stays that began before
// the discard time, or that are still open at the end, are not counted (reported as censored). The
// stay bookkeeping is analysis/ZoneStays.hpp, shared with the database job's reference RTD.
#include <algorithm>
#include <memory>

#include "analysis/ZoneStays.hpp"
#include "geometry/SprayZone.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace {

class ResidenceTimeEffect final : public TracerEffect {
 public:
  explicit ResidenceTimeEffect(TracerContext& ctx) : zone_(ctx.scene.spray.spray_zone, ctx.apparatus), stays_(ctx.cloud.size()) {
    for (std::size_t i = 0; i < ctx.cloud.size(); ++i) {
      if (zone_.contains(ctx.cloud.position(i))) stays_.startInside(i);
    }
  }

  std::size_t allocatedBytes() const override {
    return (stays_.members() + stays_.durationCounts().capacity()) * sizeof(std::int64_t) +
           holdup_.capacity() * sizeof(std::int32_t);
  }

  void afterMove(TracerContext& ctx) override {
    const std::int64_t n = std::int64_t(stays_.members());
    const std::int64_t step = ctx.step;
    const std::int64_t discard = ctx.discardSteps;
    const double* x = ctx.cloud.x.data();
    const double* y = ctx.cloud.y.data();
    const double* z = ctx.cloud.z.data();
    const std::int64_t* entry = stays_.entries();
    constexpr std::int64_t kOutside = ZoneStays::kOutside;
    constexpr std::int64_t kBlock = 256;
    std::int64_t inside = 0;
    std::vector<std::int64_t> finished;  // durations in steps of stays ending now
#pragma omp parallel if (n > kParallelThreshold)
    {
      std::vector<std::int64_t> local;
#pragma omp for schedule(static) reduction(+ : inside)
      for (std::int64_t b = 0; b < (n + kBlock - 1) / kBlock; ++b) {
        const std::int64_t i0 = b * kBlock;
        const int count = int(std::min(kBlock, n - i0));
        // Who is inside, and who entered or left (few): only those change the books.
        std::int64_t in[kBlock], changed[kBlock];
        std::int64_t insideHere = 0, changes = 0;
#pragma omp simd
        for (int k = 0; k < count; ++k) in[k] = zone_.inCone(x[i0 + k], y[i0 + k], z[i0 + k]);
        if (zone_.hasShadows()) {
          for (int k = 0; k < count; ++k) in[k] = in[k] && !zone_.shadowed(x[i0 + k], y[i0 + k]);
        }
#pragma omp simd reduction(+ : insideHere, changes)
        for (int k = 0; k < count; ++k) {
          changed[k] = in[k] != std::int64_t(entry[i0 + k] != kOutside);
          insideHere += in[k], changes += changed[k];
        }
        inside += insideHere;
        if (changes == 0) continue;
        for (int k = 0; k < count; ++k) {
          if (!changed[k]) continue;
          const std::int64_t d = stays_.observe(std::size_t(i0 + k), in[k] != 0, step, discard);
          if (d >= 0) local.push_back(d);
        }
      }
#pragma omp critical
      finished.insert(finished.end(), local.begin(), local.end());
    }
    stays_.addDurations(finished);
    if (ctx.collecting()) holdup_.push_back(std::int32_t(inside));
  }

  void writeResults(const TracerContext& ctx, h5::File& out, nlohmann::json& summary) const override {
    const double dt = ctx.dt;
    const StayStatistics st = stays_.statistics(dt, ctx.scene.outputs.residence_time_bins);
    double holdupMean = 0.0;
    for (const auto h : holdup_) holdupMean += h;
    holdupMean = holdup_.empty() ? 0.0 : holdupMean / double(holdup_.size());
    std::vector<double> holdupParticles(holdup_.size());
    for (std::size_t s = 0; s < holdup_.size(); ++s) {
      holdupParticles[s] = holdup_[s] * ctx.cloud.particlesPerTracer;
    }
    out.write("/residence_time/duration_steps_counts", stays_.durationCounts());
    out.write("/residence_time/histogram_edges", st.edges);
    out.write("/residence_time/histogram_counts", st.counts);
    out.write("/holdup/particles", holdupParticles);
    out.setAttribute("/holdup/particles", "dt", dt);
    out.setAttribute("/holdup/particles", "t0", double(ctx.discardSteps) * dt);
    summary["residence_time"] = st.toJson();
    // Stays per tracer per second of the collected time: per particle too, as a tracer's particles
    // move with it (the calibration's crossing rate, analysis/StayComparison.hpp).
    const double collected = double(holdup_.size()) * dt * double(ctx.cloud.size());
    summary["residence_time"]["crossings_per_tracer_per_s"] = collected > 0.0 ? double(st.stays) / collected : 0.0;
    summary["holdup"] = {{"mean", holdupMean * ctx.cloud.particlesPerTracer},
                         {"mean_fraction", ctx.cloud.size() ? holdupMean / double(ctx.cloud.size()) : 0.0},
                         {"series_file", "result.h5:/holdup/particles"}};
  }

  void permuteTracers(TracerContext&, const std::vector<std::int32_t>& from) override { stays_.permute(from); }

  void saveState(h5::File& f, const std::string& g) const override {
    stays_.save(f, g);
    std::vector<std::int64_t> h(holdup_.begin(), holdup_.end());
    f.write(g + "/holdup", h);
  }
  void loadState(const h5::File& f, const std::string& g) override {
    stays_.load(f, g);
    const auto h = f.readInt64s(g + "/holdup");
    holdup_.assign(h.begin(), h.end());
  }

 private:
  SprayZone zone_;
  ZoneStays stays_;                   ///< entries and completed stays, in steps
  std::vector<std::int32_t> holdup_;  ///< tracers in the zone per collecting step
};

const bool registered = TracerEffectRegistry::add(
    "residence_time", {}, 31, "spray-zone holdup and residence-time distribution (Figs. 10-11)",
    [](TracerContext& c) { return std::make_unique<ResidenceTimeEffect>(c); });

}  // namespace
}  // namespace rcfd
