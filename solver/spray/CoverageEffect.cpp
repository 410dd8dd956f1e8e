// coverage: Eq. (15) per tracer from the droplets it collected per real particle, and the coverage
// distribution over the bed (the paper's Fig. 12).
#include <cstdio>
#include <memory>

#include "core/AxisTicks.hpp"
#include "core/Svg.hpp"
#include "spray/Coverage.hpp"
#include "spray/SprayState.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace {

class CoverageEffect final : public TracerEffect {
 public:
  explicit CoverageEffect(TracerContext& ctx)
      : state_(ctx.spray),
        f_(singleDropletCoverage(ctx.scene.spray.droplet_diameter, ctx.scene.particles.diameter)),
        bins_(ctx.scene.outputs.coverage_bins) {}

  /// Droplets collected per real particle, per tracer (N_coll of Eq. 15).
  std::vector<double> perParticle(const TracerContext& ctx) const {
    const double ppt = ctx.cloud.particlesPerTracer;
    std::vector<double> n(state_->tracerDroplets.size(), 0.0);
    if (ppt > 0.0) {
      for (std::size_t i = 0; i < n.size(); ++i) n[i] = state_->tracerDroplets[i] / ppt;
    }
    return n;
  }

  Distribution distribution(const TracerContext& ctx) const {
    auto phi = perParticle(ctx);
    for (double& v : phi) v = coverage(v, f_);
    return describe(std::move(phi), bins_, 0.0, 1.0);
  }

  void writeResults(const TracerContext& ctx, h5::File& out, nlohmann::json& summary) const override {
    const auto droplets = perParticle(ctx);
    std::vector<double> phi(droplets.size());
    for (std::size_t i = 0; i < phi.size(); ++i) phi[i] = coverage(droplets[i], f_);
    // Whole droplets are exact in double: the mean per particle is collected / real particles exactly.
    double collected = 0.0;
    for (double d : state_->tracerDroplets) collected += d;
    const double realParticles = ctx.cloud.particlesPerTracer * double(droplets.size());
    out.write("/coverage/per_tracer", ctx.cloud.inIdOrder(phi));
    out.write("/coverage/droplets_per_particle", ctx.cloud.inIdOrder(droplets));
    const Distribution d = describe(phi, bins_, 0.0, 1.0);
    out.write("/coverage/histogram_edges", d.edges);
    std::vector<std::int64_t> counts(d.counts.begin(), d.counts.end());
    out.write("/coverage/histogram_counts", counts);
    out.setAttribute("/coverage/per_tracer", "f", f_);
    summary["coverage"] = {{"mean", d.mean}, {"median", d.median}, {"p10", d.p10}, {"p90", d.p90},
                           {"f", f_},
                           {"histogram", {{"edges", d.edges}, {"counts", d.counts}}}};
    summary["droplets_per_tracer_mean"] = realParticles > 0.0 ? collected / realParticles : 0.0;
  }

  std::vector<std::string> writeFigures(const TracerContext& ctx, const std::string& outDir) const override {
    const Distribution d = distribution(ctx);
    long long peak = 1;
    for (auto c : d.counts) peak = std::max(peak, c);
    const double total = double(std::max<std::size_t>(1, state_->tracerDroplets.size()));
    const double top = double(peak) / total * 1.1;
    SvgDocument svg(0.0, 1.0, 0.0, top, 640, 420, 55);
    for (std::size_t b = 0; b < d.counts.size(); ++b) {
      svg.rect(d.edges[b], 0.0, d.edges[b + 1], double(d.counts[b]) / total, "#3b518b", "#fff", 0.5);
    }
    svg.line(d.median, 0.0, d.median, top, "#c00", 1.5, "5,3");
    svg.axes("surface coverage phi [-] (Eq. 15)", "fraction of particles [-]");
    char median[32];
    std::snprintf(median, sizeof median, "%.3f", d.median);
    svg.textPx(320, 20, "Coverage distribution after " + durationLabel(ctx.time()) + ", median " + median, 14,
               "middle");
    svg.save(outDir + "/coverage.svg");
    return {"coverage.svg"};
  }

 private:
  std::shared_ptr<SprayState> state_;
  double f_;
  int bins_;
};

const bool registered = TracerEffectRegistry::add(
    "coverage", {"deposition"}, 52, "Eq. (15): surface coverage per tracer and its distribution (Fig. 12)",
    [](TracerContext& c) { return std::make_unique<CoverageEffect>(c); });

}  // namespace
}  // namespace rcfd
