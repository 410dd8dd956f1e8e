// langevin_velocity: the velocity spread the cell mean u_P^rec loses, restored as an Ornstein-Uhlenbeck
// velocity on the frames' own variance. Where rising and falling particles share a cell their mean is
// slow, and tracers moving with it linger where the particles shoot through (long spray-zone stays,
// too few crossings); the variance of the particle velocities about that mean (/frames/u_p_variance,
// the granular temperature per component, at the scale of the mean) says how fast they really move.
//
// Every tracer carries a fluctuation u' (per component d: variance sigma_d^2 of its cell in the step's
// frame, memory T, mean mu_d), and the OU process is integrated exactly over the step for coefficients
// held over it, velocity and displacement together (Gillespie 1996):
//   u'_d(t + dt) = mu_d + a (u'_d - mu_d) + sigma_d s xi1,                       a = exp(-dt / T),
//   w_d          = mu_d + b (u'_d - mu_d) + sigma_d (c1 xi1 + c2 xi2) / dt,      b = T (1 - a) / dt,
// where w is the mean fluctuation over the step (the displacement over dt), s^2 = 1 - a^2, and c1, c2
// give the displacement its variance T^2 (2 dt/T - 3 + 4a - a^2) and its covariance T (1 - a)^2 with the
// end velocity; xi1, xi2 standard normal (NormalTable, from a counter-based stream per tracer and step).
// w, not the end velocity, is added to Eq. (9) over the step (TracerContext::streamVelocity, after
// velocity_streams and directed_relaxation when those are listed): where T is far below dt (a dense bed
// forgets a fluctuation between two collisions) a tracer then diffuses with sigma^2 T, as the particles
// do, not with sigma^2 dt / 2.
// T is the kinetic-theory time between collisions (at most rcfd.langevin_time). The mean
// mu_d = d(alpha_P K_d)/dx_d / alpha_P, K_d = sigma_d^2 T, capped at rcfd.u_fluc_max, is the
// well-mixed condition (Thomson 1987) in its mean-drift form: in the diffusive limit the tracer flux is
// -grad(K n) + n mu, which vanishes for n proportional to alpha_P^rec, so the fluctuation does not move
// tracers out of where the recurrence field puts them. The step's coefficients are computed per cell
// and interpolated trilinearly to the tracer.
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

#include <spdlog/spdlog.h>

#include "core/Errors.hpp"
#include "core/Permutation.hpp"
#include "tracers/CellIndex.hpp"
#include "tracers/CounterRng.hpp"
#include "tracers/NormalTable.hpp"
#include "tracers/OrnsteinUhlenbeckStep.hpp"
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
    moment_.assign(std::size_t(cells), 0.0);
    memory_.assign(std::size_t(cells), 0.0);
    steps_.assign(std::size_t(cells), OrnsteinUhlenbeckStep{});
    alpha_.assign(std::size_t(cells), 0.0);
  }

  std::size_t allocatedBytes() const override {
    return (owner_ ? 3 * tracers_ * sizeof(float) : 0) + 3 * tracers_ * sizeof(float) +
           (sigma_.capacity() + coefficients_.capacity()) * sizeof(float) +
           (moment_.capacity() + alpha_.capacity() + memory_.capacity()) * sizeof(double) +
           steps_.capacity() * sizeof(OrnsteinUhlenbeckStep);
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
    const TrilinearLocator::Constants locator = TrilinearLocator(ctx.grid, ctx.plateFacesOrNull()).constants();
    const std::int32_t corner[8] = {0, 1, locator.sy, locator.sy + 1, locator.sz, locator.sz + 1,
                                    locator.sz + locator.sy, locator.sz + locator.sy + 1};
    const double* position[3] = {ctx.cloud.x.data(), ctx.cloud.y.data(), ctx.cloud.z.data()};
    float* out[3] = {ctx.streamVelocity[0].data(), ctx.streamVelocity[1].data(), ctx.streamVelocity[2].data()};
    float* u[3] = {fluctuation_[0].data(), fluctuation_[1].data(), fluctuation_[2].data()};
    const float* coefficients = coefficients_.data();
    const double* alpha = alpha_.data();
    const CellIndexer cells(ctx.grid);
    const NormalTable& normals = NormalTable::instance();
    const bool owner = owner_;
#pragma omp parallel for schedule(static) if (std::int64_t(n) > kParallelThreshold)
    for (std::int64_t i = 0; i < std::int64_t(n); ++i) {
      // The step's coefficients at the tracer's position, trilinear between cell centres: the drift's
      // gradient within a cell then keeps the tracers' density there as alpha_P^rec varies.
      double f[3];
      const std::int32_t stencil = locator.locate(position[0][i], position[1][i], position[2][i], f[0], f[1], f[2]);
      locator.keepOnPlateSide(stencil, f[0], f[1], f[2]);
      const std::size_t base = std::size_t(stencil);
      double at[kCoefficients] = {};
      for (int k = 0; k < 8; ++k) {
        const double w = ((k & 1) ? f[0] : 1.0 - f[0]) * ((k & 2) ? f[1] : 1.0 - f[1]) * ((k & 4) ? f[2] : 1.0 - f[2]);
        const float* cell = coefficients + kCoefficients * (base + std::size_t(corner[k]));
        for (int q = 0; q < kCoefficients; ++q) at[q] += w * double(cell[q]);
      }
      double xi1[3], xi2[3];
      CounterRng rng(prefix, std::uint64_t(id[i]));
      normals.three(rng.nextU64(), xi1);
      normals.three(rng.nextU64(), xi2);
      Eigen::Vector3d next, step;
      for (int d = 0; d < 3; ++d) {
        const double mean = at[kMean + d], sigma = at[kSigma + d], deviation = double(u[d][i]) - mean;
        next[d] = mean + at[kDecay] * deviation + sigma * at[kKick] * xi1[d];
        step[d] = mean + at[kCarry] * deviation + sigma * (at[kShared] * xi1[d] + at[kOwn] * xi2[d]);
      }
      const Eigen::Vector3d here(position[0][i], position[1][i], position[2][i]);
      reflectAtWalls(ctx.apparatus, here, ctx.dt, step, next);
      // The fluctuation is the particles' own: it does not carry a tracer where the frame holds none (the
      // bed's free surface, the rim of a jet). Reflected there, as at a wall, it keeps the tracers within
      // the particle phase, whose edge the drift alone, taken between cell centres, does not hold.
      const Eigen::Vector3d end = here + ctx.dt * step;
      std::int32_t endCell;
      cells.cellsOf(1, &end.x(), &end.y(), &end.z(), &endCell);
      if (alpha[std::size_t(endCell)] <= 0.0) step = -step, next = -next;
      for (int d = 0; d < 3; ++d) {
        u[d][i] = float(next[d]);
        out[d][i] = owner ? float(step[d]) : out[d][i] + float(step[d]);
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
  /// at it, as a particle's velocity is, and so is the fluctuation carried on where it points into that
  /// wall: the walls reflect the tracer's position, and a fluctuation kept pointing into the wall for
  /// the time scale T would hold tracers against it. Most tracers are cleared by the convex
  /// half-spaces and the plates' boxes alone.
  void reflectAtWalls(const Apparatus& apparatus, const Eigen::Vector3d& p, double dt, Eigen::Vector3d& step,
                      Eigen::Vector3d& carried) const {
    const Eigen::Vector3d q = p + dt * step;
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
    const double into = step.dot(hit->normal);
    if (into >= 0.0) return;
    step -= 2.0 * into * hit->normal;
    const double carriedInto = carried.dot(hit->normal);
    if (carriedInto < 0.0) carried -= 2.0 * carriedInto * hit->normal;
  }

  /// The coefficients of every cell for this step's frame (blended like alpha_P^rec).
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
    for (std::size_t c = 0; c < cells; ++c) {
      double theta = 0.0;
      for (std::size_t d = 0; d < 3; ++d) {
        const double variance = std::max(0.0, mix(a.u_p_variance, b ? &b->u_p_variance : nullptr, 3 * c + d));
        sigma_[3 * c + d] = float(std::sqrt(variance));
        theta += variance / 3.0;
      }
      memory_[c] = memory(alpha_[c], theta);
    }
    for (std::size_t c = 0; c < cells; ++c) steps_[c] = OrnsteinUhlenbeckStep::over(ctx.dt, memory_[c]);
    for (std::size_t d = 0; d < 3; ++d) {
      for (std::size_t c = 0; c < cells; ++c) moment_[c] = alpha_[c] * double(sigma_[3 * c + d]) * sigma_[3 * c + d];
      for (std::size_t c = 0; c < cells; ++c) {
        double mean = 0.0;
        if (alpha_[c] > 0.0) {
          // The well-mixed mean: T d(alpha sigma^2)/dx / alpha, and where the step forgets the velocity
          // (carry -> 0) the part sigma^2 dT/dx that coefficients frozen over the step at its start
          // would otherwise lose, so that (alpha sigma^2 T)' / alpha in the diffusive limit.
          const double gradMoment = centralDifference(ctx, moment_, c, d);
          const double gradMemory = centralDifference(ctx, memory_, c, d);
          mean = memory_[c] * gradMoment / alpha_[c] +
                 (1.0 - steps_[c].carry) * moment_[c] / alpha_[c] * gradMemory;
          mean = std::clamp(mean, -cap_, cap_);
        }
        coefficients_[kCoefficients * c + kMean + d] = float(mean);
        coefficients_[kCoefficients * c + kSigma + d] = sigma_[3 * c + d];
      }
    }
    for (std::size_t c = 0; c < cells; ++c) {
      const OrnsteinUhlenbeckStep& step = steps_[c];
      float* k = coefficients_.data() + kCoefficients * c;
      k[kDecay] = float(step.decay);
      k[kKick] = float(step.kick);
      k[kCarry] = float(step.carry);
      k[kShared] = float(step.shared);
      k[kOwn] = float(step.own);
    }
  }

  /// d f / dx_d at cell c from its open neighbours along d (one-sided at walls and plates, 0 without
  /// any). A neighbour across a plate is not one: its particles never meet this cell's, and a gradient
  /// taken across the plate would drive the tracers beside it against the plate.
  static double centralDifference(const TracerContext& ctx, const std::vector<double>& f, std::size_t c, std::size_t d) {
    const CartesianGrid& grid = ctx.grid;
    const auto ijk = grid.cellIjk(std::int64_t(c));
    const std::uint8_t* plates = ctx.plateFacesOrNull();
    const std::uint8_t plateBit = d == 0 ? kPlateAboveX : d == 1 ? kPlateAboveY : 0;
    auto neighbour = [&](int side) -> std::int64_t {
      auto nb = ijk;
      nb[d] += side;
      if (nb[d] < 0 || nb[d] >= grid.shape[d]) return -1;
      const std::int64_t o = grid.flatIndex(nb[0], nb[1], nb[2]);
      if (plates && plateBit && (plates[side > 0 ? c : std::size_t(o)] & plateBit)) return -1;
      return ctx.openVolume[std::size_t(o)] > 0.0 ? o : -1;
    };
    const std::int64_t lo = neighbour(-1), hi = neighbour(1);
    const double span = double((lo >= 0) + (hi >= 0)) * grid.spacing[d];
    if (span <= 0.0) return 0.0;
    return ((hi >= 0 ? f[std::size_t(hi)] : f[c]) - (lo >= 0 ? f[std::size_t(lo)] : f[c])) / span;
  }

  /// The memory T: the time between collisions of kinetic theory, d sqrt(pi) / (24 alpha_P g0 sqrt(theta))
  /// with the Carnahan-Starling g0 and theta the mean of the three variances, at most rcfd.langevin_time
  /// (the dilute limit, where drag and walls end the memory).
  double memory(double alpha, double theta) const {
    const double a = std::min(alpha, 0.6);
    const double g0 = (1.0 - 0.5 * a) / std::pow(1.0 - a, 3);
    const double rate = 24.0 * a * g0 * std::sqrt(theta) / (diameter_ * std::sqrt(std::numbers::pi));
    return rate * time_ > 1.0 ? 1.0 / rate : time_;
  }

  double time_, cap_;
  bool owner_ = false;
  bool missingSpread_ = false;
  std::size_t tracers_ = 0;
  std::vector<float> fluctuation_[3];  ///< per tracer index: u' [m/s]
  std::vector<float> sigma_;           ///< per cell: sigma_x, sigma_y, sigma_z [m/s]
  /// Per cell, the exact OU step over dt for the step's frame (OrnsteinUhlenbeckStep's a, s, b, c1 / dt,
  /// c2 / dt), sigma_d and the mean mu_d (capped), padded to 12 floats.
  static constexpr int kDecay = 0, kKick = 1, kCarry = 2, kShared = 3, kOwn = 4, kSigma = 5, kMean = 8;
  static constexpr int kCoefficients = 12;
  std::vector<float> coefficients_;
  double diameter_ = 0.0;              ///< d_P [m]
  std::vector<double> moment_, alpha_, memory_;  ///< scratch per cell: alpha_P sigma_d^2, alpha_P, T
  std::vector<OrnsteinUhlenbeckStep> steps_;    ///< scratch per cell: the exact step over dt for T
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
