// probes: alpha_P of the tracers and alpha_P^rec in the cells of the scene's probe points over time
// (the paper's Fig. 7) and the penalty of Fig. 8, (1/N) ||alpha_P - alpha_P^rec||_2 per probe.
#include <cmath>
#include <memory>

#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace {

class ProbesEffect final : public TracerEffect {
 public:
  explicit ProbesEffect(TracerContext& ctx) {
    for (const auto& probe : ctx.scene.probes) {
      names_.push_back(probe.name);
      cells_.push_back(ctx.grid.flatIndexOf(probe.position));
    }
    // Keep at most ~100k samples per probe for long runs; the penalty uses every step regardless.
    stride_ = std::max<std::int64_t>(1, ctx.totalSteps / 100000);
    sumSquares_.assign(cells_.size(), 0.0);
  }

  std::size_t allocatedBytes() const override {
    return (time_.capacity() + tracer_.capacity() + recurrence_.capacity()) * sizeof(double);
  }

  void afterMove(TracerContext& ctx) override {
    // tracerAlpha holds the tracers at the start of this step, the positions the frame belongs to.
    if (!ctx.collecting()) return;
    const FrameSampler sampler = ctx.sampler();
    const bool record = (ctx.step % stride_) == 0;
    if (record) time_.push_back(ctx.time());
    for (std::size_t p = 0; p < cells_.size(); ++p) {
      const double a = ctx.tracerAlpha[std::size_t(cells_[p])];
      const double r = sampler.alphaP(cells_[p]);
      sumSquares_[p] += (a - r) * (a - r);
      if (record) {
        tracer_.push_back(a);
        recurrence_.push_back(r);
      }
    }
    ++samples_;
  }

  void writeResults(const TracerContext&, h5::File& out, nlohmann::json& summary) const override {
    const hsize_t rows = time_.size(), cols = cells_.size();
    out.write("/probes/time", time_);
    out.write("/probes/alpha_p_tracers", tracer_, {rows, cols});
    out.write("/probes/alpha_p_recurrence", recurrence_, {rows, cols});
    nlohmann::json probes = nlohmann::json::array();
    double meanPenalty = 0.0, meanRms = 0.0;
    for (std::size_t p = 0; p < cells_.size(); ++p) {
      const double n = double(std::max<std::int64_t>(samples_, 1));
      const double penalty = std::sqrt(sumSquares_[p]) / n;  // the paper's (1/N) ||.||_2
      const double rms = std::sqrt(sumSquares_[p] / n);
      meanPenalty += penalty / double(cells_.size());
      meanRms += rms / double(cells_.size());
      probes.push_back({{"name", names_[p]}, {"penalty", penalty}, {"rms", rms}});
    }
    summary["probes"] = {{"samples", samples_}, {"penalty_mean", meanPenalty}, {"rms_mean", meanRms},
                         {"per_probe", probes}};
  }

  void saveState(h5::File& f, const std::string& g) const override {
    f.write(g + "/time", time_);
    f.write(g + "/tracer", tracer_);
    f.write(g + "/recurrence", recurrence_);
    f.write(g + "/sum_squares", sumSquares_);
    f.write(g + "/samples", std::vector<std::int64_t>{samples_});
  }
  void loadState(const h5::File& f, const std::string& g) override {
    time_ = f.readDoubles(g + "/time");
    tracer_ = f.readDoubles(g + "/tracer");
    recurrence_ = f.readDoubles(g + "/recurrence");
    sumSquares_ = f.readDoubles(g + "/sum_squares");
    samples_ = f.readInt64s(g + "/samples").at(0);
  }

 private:
  std::vector<std::string> names_;
  std::vector<std::int64_t> cells_;
  std::int64_t stride_ = 1;
  std::vector<double> time_, tracer_, recurrence_;  ///< recorded series, row-major [sample][probe]
  std::vector<double> sumSquares_;
  std::int64_t samples_ = 0;
};

const bool registered = TracerEffectRegistry::add(
    "probes", {"tracer_volume_fraction"}, 30,
    "alpha_P of tracers vs alpha_P^rec at the probes over time, and the penalty score",
    [](TracerContext& c) { return std::make_unique<ProbesEffect>(c); });

}  // namespace
}  // namespace rcfd
