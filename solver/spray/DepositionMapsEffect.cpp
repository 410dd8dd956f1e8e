// deposition_maps: time-averaged deposition rate density [kg/(m3 s)] per cell, and its mid-plane slices
// z = depth/2 and x = 0 (the paper's Fig. 13), in result.h5 and as SVG heat maps.
#include <algorithm>
#include <cmath>
#include <memory>

#include "core/Svg.hpp"
#include "spray/SprayState.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace {

class DepositionMapsEffect final : public TracerEffect {
 public:
  explicit DepositionMapsEffect(TracerContext& ctx)
      : state_(ctx.spray), sum_(std::size_t(ctx.grid.cellCount()), 0.0) {}

  std::size_t allocatedBytes() const override { return sum_.capacity() * sizeof(double); }

  bool afterMoveBesideMotion() const override { return true; }
  void afterMove(TracerContext& ctx) override {
    if (!ctx.collecting()) return;
    // cellDeposit is 0 outside depositCells: adding only those cells gives the same sums.
    const auto& dep = state_->cellDeposit;
    for (const std::int32_t c : state_->depositCells) sum_[std::size_t(c)] += dep[std::size_t(c)];
    ++samples_;
  }

  /// Rate density per cell [kg/(m3 s)].
  std::vector<double> rateDensity(const TracerContext& ctx) const {
    std::vector<double> rate(sum_.size(), 0.0);
    const double seconds = double(samples_) * ctx.dt;
    if (!(seconds > 0.0)) return rate;
    for (std::size_t c = 0; c < rate.size(); ++c) {
      const double v = ctx.openVolume[c];
      rate[c] = v > 0.0 ? sum_[c] * state_->dropletMass / (v * seconds) : 0.0;
    }
    return rate;
  }

  /// Slice at z = depth/2 (plane "z": nx x ny) or x = 0 (plane "x": nz x ny).
  static std::vector<double> slice(const TracerContext& ctx, const std::vector<double>& field, char plane,
                                   int& width, int& height) {
    const auto& g = ctx.grid;
    height = g.shape[1];
    if (plane == 'z') {
      width = g.shape[0];
      const int k = g.cellOf(Eigen::Vector3d(0.0, 0.0, ctx.apparatus.depth() / 2))[2];
      std::vector<double> out(std::size_t(width) * height);
      for (int j = 0; j < height; ++j)
        for (int i = 0; i < width; ++i) out[std::size_t(j) * width + i] = field[std::size_t(g.flatIndex(i, j, k))];
      return out;
    }
    width = g.shape[2];
    const int i = g.cellOf(Eigen::Vector3d(0.0, 0.0, 0.0))[0];
    std::vector<double> out(std::size_t(width) * height);
    for (int j = 0; j < height; ++j)
      for (int k = 0; k < width; ++k) out[std::size_t(j) * width + k] = field[std::size_t(g.flatIndex(i, j, k))];
    return out;
  }

  void writeResults(const TracerContext& ctx, h5::File& out, nlohmann::json& summary) const override {
    const auto rate = rateDensity(ctx);
    const auto& s = ctx.grid.shape;
    out.write("/deposition_maps/rate_density", rate, {hsize_t(s[2]), hsize_t(s[1]), hsize_t(s[0])});
    int w = 0, h = 0;
    const auto z = slice(ctx, rate, 'z', w, h);
    out.write("/deposition_maps/midplane_z", z, {hsize_t(h), hsize_t(w)});
    const auto x = slice(ctx, rate, 'x', w, h);
    out.write("/deposition_maps/midplane_x", x, {hsize_t(h), hsize_t(w)});
    out.setAttribute("/deposition_maps/rate_density", "unit", std::string("kg/(m3 s)"));
    summary["deposition_maps"] = {{"max_rate_density", rate.empty() ? 0.0 : *std::max_element(rate.begin(), rate.end())},
                                  {"samples", samples_}};
  }

  std::vector<std::string> writeFigures(const TracerContext& ctx, const std::string& outDir) const override {
    const auto rate = rateDensity(ctx);
    const auto& g = ctx.grid;
    const Eigen::Vector3d lo = g.origin, hi = g.upperCorner();
    std::vector<std::string> files;
    for (char plane : {'z', 'x'}) {
      int w = 0, h = 0;
      auto values = slice(ctx, rate, plane, w, h);
      const double peak = std::max(1e-300, *std::max_element(values.begin(), values.end()));
      for (double& v : values) v = v > 0.0 ? v / peak : std::nan("");
      const double x0 = plane == 'z' ? lo.x() : lo.z(), x1 = plane == 'z' ? hi.x() : hi.z();
      const double aspect = (hi.y() - lo.y()) / (x1 - x0);
      const double width = 420, height = std::min(900.0, 80 + 340 * aspect);
      SvgDocument svg(x0, x1, lo.y(), hi.y(), width, height, 50);
      svg.heatmap(values, w, h, x0, x1, lo.y(), hi.y());
      svg.axes(plane == 'z' ? "x [m]" : "z [m]", "y [m]", 4, 6);
      svg.textPx(width / 2, 18,
                 std::string("deposition rate density, ") + (plane == 'z' ? "z = depth/2" : "x = 0") +
                     " (max " + std::to_string(peak).substr(0, 8) + " kg/m3/s)",
                 12, "middle");
      const std::string name = std::string("deposition_") + plane + ".svg";
      svg.save(outDir + "/" + name);
      files.push_back(name);
    }
    return files;
  }

  void saveState(h5::File& f, const std::string& g) const override {
    f.write(g + "/sum", sum_);
    f.write(g + "/samples", std::vector<std::int64_t>{samples_});
  }
  void loadState(const h5::File& f, const std::string& g) override {
    sum_ = f.readDoubles(g + "/sum");
    samples_ = f.readInt64s(g + "/samples").at(0);
  }

 private:
  std::shared_ptr<SprayState> state_;
  std::vector<double> sum_;  ///< droplets deposited per cell over the collecting steps
  std::int64_t samples_ = 0;
};

const bool registered = TracerEffectRegistry::add(
    "deposition_maps", {"deposition"}, 53,
    "time-averaged deposition rate density on the mid-planes z = depth/2 and x = 0 (Fig. 13)",
    [](TracerContext& c) { return std::make_unique<DepositionMapsEffect>(c); });

}  // namespace
}  // namespace rcfd
