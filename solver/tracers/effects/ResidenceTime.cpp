// residence_time: spray-zone holdup over time and the duration of every stay of a tracer in the spray
// zone (the paper's Figs. 10-11). Durations are counted in whole steps, so the histogram and its sums
// are integers: identical for any thread count and across checkpoint/resume. Stays that began before
// the discard time, or that are still open at the end, are not counted (reported as censored).
#include <algorithm>
#include <memory>

#include "geometry/SprayZone.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace {

constexpr std::int64_t kOutside = -1;
constexpr std::int64_t kUnknownEntry = -2;  ///< inside at the start: the entry time is unknown

class ResidenceTimeEffect final : public TracerEffect {
 public:
  explicit ResidenceTimeEffect(TracerContext& ctx)
      : zone_(ctx.scene.spray.spray_zone), entry_(ctx.cloud.size(), kOutside) {
    for (std::size_t i = 0; i < ctx.cloud.size(); ++i) {
      if (zone_.contains(ctx.cloud.position(i))) entry_[i] = kUnknownEntry;
    }
  }

  std::size_t allocatedBytes() const override {
    return entry_.capacity() * sizeof(std::int64_t) + durationCounts_.capacity() * sizeof(std::int64_t) +
           holdup_.capacity() * sizeof(std::int32_t);
  }

  void afterMove(TracerContext& ctx) override {
    const std::int64_t n = std::int64_t(entry_.size());
    const std::int64_t step = ctx.step;
    const std::int64_t discard = ctx.discardSteps;
    std::int64_t inside = 0;
    std::vector<std::int64_t> finished;  // durations in steps of stays ending now
#pragma omp parallel if (n > kParallelThreshold)
    {
      std::vector<std::int64_t> local;
#pragma omp for schedule(static) reduction(+ : inside)
      for (std::int64_t i = 0; i < n; ++i) {
        const bool in = zone_.contains(ctx.cloud.position(std::size_t(i)));
        std::int64_t& e = entry_[std::size_t(i)];
        if (in) {
          ++inside;
          if (e == kOutside) e = step;  // entered during this step
        } else if (e != kOutside) {
          if (e >= discard) local.push_back(step - e);
          e = kOutside;
        }
      }
#pragma omp critical
      finished.insert(finished.end(), local.begin(), local.end());
    }
    for (const std::int64_t d : finished) {  // integer counts: the merge order does not matter
      if (std::size_t(d) >= durationCounts_.size()) durationCounts_.resize(std::size_t(d) + 1, 0);
      ++durationCounts_[std::size_t(d)];
    }
    if (ctx.collecting()) holdup_.push_back(std::int32_t(inside));
  }

  void writeResults(const TracerContext& ctx, h5::File& out, nlohmann::json& summary) const override {
    const double dt = ctx.dt;
    std::int64_t stays = 0, sumSteps = 0;
    for (std::size_t d = 0; d < durationCounts_.size(); ++d) {
      stays += durationCounts_[d];
      sumSteps += std::int64_t(d) * durationCounts_[d];
    }
    // Median from the integer histogram.
    double median = 0.0;
    for (std::int64_t d = 0, seen = 0; d < std::int64_t(durationCounts_.size()); ++d) {
      seen += durationCounts_[std::size_t(d)];
      if (2 * seen >= stays && stays > 0) {
        median = double(d) * dt;
        break;
      }
    }
    const int bins = std::max(1, ctx.scene.outputs.residence_time_bins);
    const double maxDuration = std::max(1.0, double(durationCounts_.size())) * dt;
    std::vector<double> edges(std::size_t(bins) + 1);
    std::vector<std::int64_t> counts(std::size_t(bins), 0);
    for (int b = 0; b <= bins; ++b) edges[std::size_t(b)] = maxDuration * b / bins;
    for (std::size_t d = 0; d < durationCounts_.size(); ++d) {
      const int b = std::min(bins - 1, int(double(d) * dt / maxDuration * bins));
      counts[std::size_t(b)] += durationCounts_[d];
    }
    std::int64_t open = 0;
    for (const auto e : entry_) open += (e != kOutside);
    double holdupMean = 0.0;
    for (const auto h : holdup_) holdupMean += h;
    holdupMean = holdup_.empty() ? 0.0 : holdupMean / double(holdup_.size());
    std::vector<double> holdupParticles(holdup_.size());
    for (std::size_t s = 0; s < holdup_.size(); ++s) {
      holdupParticles[s] = holdup_[s] * ctx.cloud.particlesPerTracer;
    }
    out.write("/residence_time/duration_steps_counts", durationCounts_);
    out.write("/residence_time/histogram_edges", edges);
    out.write("/residence_time/histogram_counts", counts);
    out.write("/holdup/particles", holdupParticles);
    out.setAttribute("/holdup/particles", "dt", dt);
    out.setAttribute("/holdup/particles", "t0", double(ctx.discardSteps) * dt);
    summary["residence_time"] = {
        {"mean_s", stays > 0 ? double(sumSteps) / double(stays) * dt : 0.0},
        {"median_s", median},
        {"stays", stays},
        {"censored", open},
        {"histogram", {{"edges", edges}, {"counts", counts}}}};
    summary["holdup"] = {{"mean", holdupMean * ctx.cloud.particlesPerTracer},
                         {"mean_fraction", ctx.cloud.size() ? holdupMean / double(ctx.cloud.size()) : 0.0},
                         {"series_file", "result.h5:/holdup/particles"}};
  }

  void saveState(h5::File& f, const std::string& g) const override {
    f.write(g + "/entry", entry_);
    f.write(g + "/duration_counts", durationCounts_);
    std::vector<std::int64_t> h(holdup_.begin(), holdup_.end());
    f.write(g + "/holdup", h);
  }
  void loadState(const h5::File& f, const std::string& g) override {
    entry_ = f.readInt64s(g + "/entry");
    durationCounts_ = f.readInt64s(g + "/duration_counts");
    const auto h = f.readInt64s(g + "/holdup");
    holdup_.assign(h.begin(), h.end());
  }

 private:
  SprayZone zone_;
  std::vector<std::int64_t> entry_;           ///< step a tracer entered, or kOutside / kUnknownEntry
  std::vector<std::int64_t> durationCounts_;  ///< stays per duration in steps
  std::vector<std::int32_t> holdup_;          ///< tracers in the zone per collecting step
};

const bool registered = TracerEffectRegistry::add(
    "residence_time", {}, 31, "spray-zone holdup and residence-time distribution (Figs. 10-11)",
    [](TracerContext& c) { return std::make_unique<ResidenceTimeEffect>(c); });

}  // namespace
}  // namespace rcfd
