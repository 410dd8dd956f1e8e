// langevin_velocity: the velocity spread the cell mean u_P^rec loses, restored as an Ornstein-Uhlenbeck
// velocity on the frames' own variance. Where rising and falling particles share a cell their mean is
// slow, and tracers moving with it linger where the particles shoot through (long spray-zone stays,
// too few crossings); the variance of the particle velocities about that mean (/frames/u_p_variance,
// the granular temperature per component, at the scale of the mean) says how fast they really move.
// Every tracer carries a fluctuation u' (per component d, variance sigma_d^2 of its cell in the step's
// frame), integrated exactly over the step for constant coefficients:
//   u'_d <- a u'_d + (1 - a) T g_d + sigma_d sqrt(1 - a^2) xi,   a = exp(-dt / T),
// with T the kinetic-theory time between collisions (at most rcfd.langevin_time), xi standard normal
// (NormalTable, from a counter-based stream per tracer and step), and the drift g_d = d(alpha_P sigma_d^2)/dx_d / alpha_P: in the diffusive limit the tracer flux is then
// -T grad(sigma^2 n) + n T g, which vanishes for n proportional to alpha_P^rec, so the fluctuation
// does not move tracers out of where the recurrence field puts them (the well-mixed condition of
// Thomson 1987, in its mean-drift form). |T g| is capped at rcfd.u_fluc_max. u' is added to Eq. (9)
// over the step (TracerContext::streamVelocity, after velocity_streams and directed_relaxation when
// those are listed). The step's coefficients a, sigma_d sqrt(1 - a^2) and (1 - a) T g_d are computed per
// cell and interpolated trilinearly to the tracer.
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

#include <spdlog/spdlog.h>

#include "core/Errors.hpp"
#include "core/Permutation.hpp"
#include "tracers/CounterRng.hpp"
#include "tracers/NormalTable.hpp"
#include "tracers/TracerEffect.hpp"
#include "tracers/Trilinear.hpp"

namespace rcfd {
namespace {

class LangevinVelocityEffect final : public TracerEffect {
 public:
  explicit LangevinVelocityEffect(TracerContext& ctx)
      : time_(ctx.scene.rcfd.langevin_time), cap_(ctx.scene.rcfd.u_fluc_max), tracers_(ctx.cloud.size()) {
    const std::size_t n = tracers_;
    owner_ = ctx.streamVelocity[0].size() != n;
    if (owner_) {
      for (auto& v : ctx.streamVelocity) v.assign(n, 0.0f);
    }
    for (auto& v : fluctuation_) v.assign(n, 0.0f);
    halfSpaces_ = ctx.apparatus.convexHalfSpaces();
    for (const auto& plate : ctx.apparatus.holes()) {
      Eigen::Vector2d lo = plate[0], hi = plate[0];
      for (const auto& v : plate) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
      plates_.push_back({lo, hi});
    }
    margin_ = 2.0 * ctx.apparatus.boundaryTolerance();
    const std::int64_t cells = ctx.grid.cellCount();
    sigma_.assign(3 * std::size_t(cells), 0.0f);
    coefficients_.assign(kCoefficients * std::size_t(cells), 0.0f);
    diameter_ = ctx.scene.particles.diameter;
    drift_.assign(3 * std::size_t(cells), 0.0f);
    moment_.assign(std::size_t(cells), 0.0);
    alpha_.assign(std::size_t(cells), 0.0);
  }

  std::size_t allocatedBytes() const override {
    return (owner_ ? 3 * tracers_ * sizeof(float) : 0) + 3 * tracers_ * sizeof(float) +
           (sigma_.capacity() + drift_.capacity() + coefficients_.capacity()) * sizeof(float) +
           (moment_.capacity() + alpha_.capacity()) * sizeof(double);
  }

  void beforeMove(TracerContext& ctx) override {
    if (!ctx.frame->hasVelocitySpread()) {
      // A database without the spread (from elsewhere, or written for a scene without the effect):
      // the tracers move without the fluctuation, and the log and summary say so.
      if (!missingSpread_) {
        missingSpread_ = true;
        spdlog::warn("langevin_velocity: {} holds no velocity spread (/frames/u_p_variance); the tracers move "
                     "without the Langevin fluctuation",
                     ctx.database ? ctx.database->path() : std::string("the database"));
      }
      if (owner_) {
        for (auto& v : ctx.streamVelocity) std::fill(v.begin(), v.end(), 0.0f);
      }
      return;
    }
    cellFields(ctx);
    const std::size_t n = ctx.cloud.size();
    const CounterRngPrefix prefix(ctx.seed, RngPurpose::Langevin, std::uint64_t(ctx.step));
    const std::int32_t* id = ctx.cloud.id.data();
    const TrilinearLocator::Constants locator = TrilinearLocator(ctx.grid).constants();
    const std::int32_t corner[8] = {0, 1, locator.sy, locator.sy + 1, locator.sz, locator.sz + 1,
                                    locator.sz + locator.sy, locator.sz + locator.sy + 1};
    const double* position[3] = {ctx.cloud.x.data(), ctx.cloud.y.data(), ctx.cloud.z.data()};
    float* out[3] = {ctx.streamVelocity[0].data(), ctx.streamVelocity[1].data(), ctx.streamVelocity[2].data()};
    float* u[3] = {fluctuation_[0].data(), fluctuation_[1].data(), fluctuation_[2].data()};
    const float* coefficients = coefficients_.data();
    const NormalTable& normals = NormalTable::instance();
    const bool owner = owner_;
#pragma omp parallel for schedule(static) if (std::int64_t(n) > kParallelThreshold)
    for (std::int64_t i = 0; i < std::int64_t(n); ++i) {
      // The step's coefficients at the tracer's position, trilinear between cell centres: the drift's
      // gradient within a cell then keeps the tracers' density there as alpha_P^rec varies.
      double f[3];
      const std::size_t base = std::size_t(locator.locate(position[0][i], position[1][i], position[2][i], f[0], f[1], f[2]));
      double at[kCoefficients] = {};
      for (int k = 0; k < 8; ++k) {
        const double w = ((k & 1) ? f[0] : 1.0 - f[0]) * ((k & 2) ? f[1] : 1.0 - f[1]) * ((k & 4) ? f[2] : 1.0 - f[2]);
        const float* cell = coefficients + kCoefficients * (base + std::size_t(corner[k]));
        for (int q = 0; q < kCoefficients; ++q) at[q] += w * double(cell[q]);
      }
      double xi[3];
      CounterRng rng(prefix, std::uint64_t(id[i]));
      normals.three(rng.nextU64(), xi);
      Eigen::Vector3d next;
      for (int d = 0; d < 3; ++d) next[d] = at[0] * double(u[d][i]) + at[4 + d] + at[1 + d] * xi[d];
      reflectAtWalls(ctx.apparatus, Eigen::Vector3d(position[0][i], position[1][i], position[2][i]), ctx.dt, next);
      for (int d = 0; d < 3; ++d) {
        u[d][i] = float(next[d]);
        out[d][i] = owner ? float(next[d]) : out[d][i] + float(next[d]);
      }
    }
  }

  void writeResults(const TracerContext&, h5::File&, nlohmann::json& summary) const override {
    summary["langevin_velocity"] = {
        {"active", !missingSpread_},
        {"note", missingSpread_ ? "the database holds no velocity spread (/frames/u_p_variance): the tracers moved "
                                  "without the Langevin fluctuation"
                                : "Ornstein-Uhlenbeck fluctuation on the frames' velocity variance"}};
  }

  void permuteTracers(TracerContext&, const std::vector<std::int32_t>& from) override {
    for (auto& v : fluctuation_) applyPermutation(v, from);
  }

  void saveState(h5::File& f, const std::string& g) const override {
    f.write(g + "/u_x", fluctuation_[0]);
    f.write(g + "/u_y", fluctuation_[1]);
    f.write(g + "/u_z", fluctuation_[2]);
  }
  void loadState(const h5::File& f, const std::string& g) override {
    const char* names[3] = {"/u_x", "/u_y", "/u_z"};
    for (int d = 0; d < 3; ++d) {
      auto v = f.readFloats(g + names[d]);
      if (v.size() != tracers_) throw InputError(f.path(), g + names[d], "does not hold one velocity per tracer");
      fluctuation_[std::size_t(d)] = std::move(v);
    }
  }

 private:
  /// A fluctuation that would carry the tracer through a wall or plate within the step is reflected
  /// at it, as a particle's velocity is: the walls reflect the tracer's position, and a fluctuation
  /// kept pointing into the wall for the time scale T would hold tracers against it. Most tracers are
  /// cleared by the convex half-spaces and the plates' boxes alone.
  void reflectAtWalls(const Apparatus& apparatus, const Eigen::Vector3d& p, double dt, Eigen::Vector3d& u) const {
    const Eigen::Vector3d q = p + dt * u;
    bool clear = true;
    for (const auto& h : halfSpaces_) clear = clear && h.n.dot(q) - h.c >= margin_;
    for (const auto& b : plates_) {
      const double lo[2] = {std::min(p.x(), q.x()), std::min(p.y(), q.y())};
      const double hi[2] = {std::max(p.x(), q.x()), std::max(p.y(), q.y())};
      clear = clear && (hi[0] < b.lo.x() - margin_ || lo[0] > b.hi.x() + margin_ || hi[1] < b.lo.y() - margin_ ||
                        lo[1] > b.hi.y() + margin_);
    }
    if (clear || apparatus.signedDistance(p) < -apparatus.boundaryTolerance()) return;
    const auto hit = apparatus.firstIntersection(p, q);
    if (!hit) return;
    const double into = u.dot(hit->normal);
    if (into < 0.0) u -= 2.0 * into * hit->normal;
  }

  /// sigma_d and the drift T g_d of every cell for this step's frame (blended like alpha_P^rec).
  void cellFields(const TracerContext& ctx) {
    const FieldFrame& a = *ctx.frame;
    const FieldFrame* b = ctx.nextFrame.get();
    const double blend = b ? ctx.blend : 0.0;
    const CartesianGrid& grid = ctx.grid;
    const std::size_t cells = std::size_t(grid.cellCount());
    auto mix = [&](const std::vector<float>& fa, const std::vector<float>* fb, std::size_t k) {
      return fb ? (1.0 - blend) * double(fa[k]) + blend * double((*fb)[k]) : double(fa[k]);
    };
    for (std::size_t c = 0; c < cells; ++c) alpha_[c] = ctx.openVolume[c] > 0.0 ? mix(a.alpha_p, b ? &b->alpha_p : nullptr, c) : 0.0;
    for (int d = 0; d < 3; ++d) {
      for (std::size_t c = 0; c < cells; ++c) {
        const double variance = std::max(0.0, mix(a.u_p_variance, b ? &b->u_p_variance : nullptr, 3 * c + std::size_t(d)));
        sigma_[3 * c + std::size_t(d)] = float(std::sqrt(variance));
        moment_[c] = alpha_[c] * variance;
      }
      const double h = grid.spacing[d];
      for (std::size_t c = 0; c < cells; ++c) {
        double g = 0.0;
        if (alpha_[c] > 0.0) {
          const auto ijk = grid.cellIjk(std::int64_t(c));
          auto neighbour = [&](int side) -> std::int64_t {
            auto nb = ijk;
            nb[std::size_t(d)] += side;
            if (nb[std::size_t(d)] < 0 || nb[std::size_t(d)] >= grid.shape[std::size_t(d)]) return -1;
            const std::int64_t o = grid.flatIndex(nb[0], nb[1], nb[2]);
            return ctx.openVolume[std::size_t(o)] > 0.0 ? o : -1;
          };
          const std::int64_t lo = neighbour(-1), hi = neighbour(1);
          const double fLo = lo >= 0 ? moment_[std::size_t(lo)] : moment_[c];
          const double fHi = hi >= 0 ? moment_[std::size_t(hi)] : moment_[c];
          const double span = double((lo >= 0) + (hi >= 0)) * h;
          if (span > 0.0) g = (fHi - fLo) / span / alpha_[c];
        }
        drift_[3 * c + std::size_t(d)] = float(g);
      }
    }
    // The memory: the time between collisions of kinetic theory, d sqrt(pi) / (24 alpha_P g0 sqrt(theta))
    // with the Carnahan-Starling g0 and theta the mean of the three variances, at most rcfd.langevin_time
    // (the dilute limit, where drag and walls end the memory). Then the exact OU step's coefficients.
    for (std::size_t c = 0; c < cells; ++c) {
      const double a = std::min(alpha_[c], 0.6);
      const double theta = (double(sigma_[3 * c]) * sigma_[3 * c] + double(sigma_[3 * c + 1]) * sigma_[3 * c + 1] +
                            double(sigma_[3 * c + 2]) * sigma_[3 * c + 2]) / 3.0;
      const double g0 = (1.0 - 0.5 * a) / std::pow(1.0 - a, 3);
      const double rate = 24.0 * a * g0 * std::sqrt(theta) / (diameter_ * std::sqrt(std::numbers::pi));
      const double memory = rate * time_ > 1.0 ? 1.0 / rate : time_;
      const double decay = std::exp(-ctx.dt / memory);
      const double kick = std::sqrt(std::max(0.0, 1.0 - decay * decay));
      float* k = coefficients_.data() + kCoefficients * c;
      k[0] = float(decay);
      for (int d = 0; d < 3; ++d) {
        k[1 + d] = float(double(sigma_[3 * c + std::size_t(d)]) * kick);
        k[4 + d] = float((1.0 - decay) * std::clamp(memory * double(drift_[3 * c + std::size_t(d)]), -cap_, cap_));
      }
    }
  }

  double time_, cap_;
  bool owner_ = false;
  bool missingSpread_ = false;
  std::size_t tracers_ = 0;
  std::vector<float> fluctuation_[3];  ///< per tracer index: u' [m/s]
  std::vector<float> sigma_;           ///< per cell: sigma_x, sigma_y, sigma_z [m/s]
  std::vector<float> drift_;           ///< per cell: g_x, g_y, g_z [m/s2]
  /// Per cell, the exact OU step over dt for the step's frame: a = exp(-dt / T), sigma_d sqrt(1 - a^2)
  /// and (1 - a) T g_d (capped), padded to 8 floats.
  static constexpr int kCoefficients = 8;
  std::vector<float> coefficients_;
  double diameter_ = 0.0;              ///< d_P [m]
  std::vector<double> moment_, alpha_; ///< scratch: alpha_P sigma_d^2 and alpha_P per cell
  struct PlateBox {
    Eigen::Vector2d lo, hi;
  };
  std::vector<Apparatus::HalfSpace> halfSpaces_;
  std::vector<PlateBox> plates_;
  double margin_ = 0.0;
};

const bool registered = TracerEffectRegistry::add(
    "langevin_velocity", {"transport", "tracer_volume_fraction"}, 13,
    "Langevin velocity: every tracer carries an Ornstein-Uhlenbeck fluctuation with its cell's variance of the "
    "particle velocities (needs the frames' velocity spread) and time scale rcfd.langevin_time, with the drift "
    "that keeps tracers distributed as alpha_P^rec",
    [](TracerContext& c) { return std::make_unique<LangevinVelocityEffect>(c); }, true, true);

}  // namespace
}  // namespace rcfd
