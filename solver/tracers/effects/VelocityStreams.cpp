// velocity_streams: the two-stream conditional velocity model. Where particles moving up and particles
// moving down share a cell (the spout's edge, the fountain, the annulus beside a jet), the cell's mean
// u_P^rec is slow although no particle is: tracers moving with the mean linger where real particles
// shoot through. The database job records, per cell and frame, the share f of the particle volume
// moving up and the mean velocities u_up and u_down of the two parts (FieldFrame's velocity spread),
// with f u_up + (1 - f) u_down = u_P^rec.
//
// Each tracer belongs to a stream (up or down) and moves as that stream's volume flux carries it: the
// kernel adds (stream displacement over the step) / dt - u_P^rec to Eq. (9), keeping its walls. Two
// things change a tracer's stream:
//  - Conversion, where a stream's flux converges (the top of a fountain, where rising particles turn;
//    a wall a falling stream runs into): in such a cell the stream's tracers pass to the other stream
//    at the rate the flux converges, in continuous time along their path (faceFluxes(),
//    streamDisplacement()).
//  - A correction of each cell's share towards the database's, for what the conversion of a frame
//    does not capture (the shares' change in time, noise): beyond the counting noise of the cell's
//    tracers, with the fewest switches.
// The expected share of a cell's tracers is then f, so their expected mean velocity is u_P^rec: the
// flux, and with it alpha_P^rec, is that of Eq. (9) alone. A tracer keeps its stream as long as the
// fluxes and shares allow, which is what lets it cross the spray zone as fast as the particles do.
//
// What it needs: per-frame shares that mean something, i.e. several particles per cell. On analytic
// databases it reproduces the particles' stays (tests/tracers/test_velocity_streams.cpp); on the
// built-in quick slices, about one parcel per spray-zone cell, it is about as close as Eq. (9) alone
// (docs/calibration.md, "Regimes").
//
// Blended between the step's frames. Random numbers from the tracer's counter-based stream (purpose
// Streams): bit-identical for any thread count and across a checkpoint. Tracers in free flight keep
// their own velocity (the kernel ignores the offset there).
#include <algorithm>
#include <cmath>
#include <memory>

#include "core/Errors.hpp"
#include "core/Permutation.hpp"
#include "tracers/CounterRng.hpp"
#include "tracers/Trilinear.hpp"
#include "tracers/TracerEffect.hpp"
#include "tracers/TracerIntegrator.hpp"

namespace rcfd {
namespace {

class VelocityStreamsEffect final : public TracerEffect {
 public:
  explicit VelocityStreamsEffect(TracerContext& ctx) {
    if (!ctx.database || !ctx.database->hasVelocitySpread()) {
      throw InputError(ctx.database ? ctx.database->path() : "(no database)", kVelocitySpreadFields[0].path,
                       "the effect velocity_streams needs the velocity spread of the frames; this database has "
                       "none (the database job writes it)");
    }
    const std::size_t n = ctx.cloud.size();
    up_.assign(n, 0);
    for (auto& v : ctx.streamVelocity) v.assign(n, 0.0f);
    upCount_.assign(std::size_t(ctx.grid.cellCount()), 0);
    midpoint_ = tracerIntegrator(ctx.scene) == TracerIntegrator::Midpoint;
  }

  std::size_t allocatedBytes() const override {
    return up_.capacity() * sizeof(std::int8_t) + upCount_.capacity() * sizeof(std::int32_t) +
           3 * up_.size() * sizeof(float) +
           (upShare_.capacity() + upField_.capacity() + downField_.capacity() + meanField_.capacity() +
            alpha_.capacity() + upToDown_.capacity() + downToUp_.capacity() + upFaces_.capacity() +
            downFaces_.capacity()) *
               sizeof(float);
  }

  void beforeMove(TracerContext& ctx) override {
    const std::int64_t n = std::int64_t(ctx.cloud.size());
    const std::int32_t* cell = ctx.tracerCell.data();
    const std::int32_t* count = ctx.tracerCount.data();
    buildStepFields(ctx);
    if (initialised_) {
      std::fill(upCount_.begin(), upCount_.end(), 0);
      for (std::int64_t i = 0; i < n; ++i) upCount_[std::size_t(cell[i])] += up_[std::size_t(i)];
    }
    const CounterRngPrefix prefix(ctx.seed, RngPurpose::Streams, std::uint64_t(ctx.step));
    const std::int32_t* ids = ctx.cloud.id.data();
    float* ox = ctx.streamVelocity[0].data();
    float* oy = ctx.streamVelocity[1].data();
    float* oz = ctx.streamVelocity[2].data();
    const FrameSampler sampler = ctx.sampler();
    const TrilinearLocator& locator = sampler.locator();
    const double halfShare = midpoint_ ? 0.5 : 0.0;
    std::int64_t switches = 0, upTracers = 0;
    const bool first = !initialised_;
#pragma omp parallel for schedule(static) reduction(+ : switches, upTracers) if (n > kParallelThreshold)
    for (std::int64_t i = 0; i < n; ++i) {
      const std::size_t c = std::size_t(cell[i]);
      const double f = double(upShare_[c]);
      std::int8_t& s = up_[std::size_t(i)];
      CounterRng rng(prefix, std::uint64_t(ids[i]));
      const double u = rng.uniform();
      if (first) {
        s = u < f ? 1 : 0;  // the streams in the database's shares
      } else {
        // The cell's share corrected towards the database's with the fewest switches, by what exceeds
        // the counting noise of its n tracers (sigma = sqrt(f (1 - f) / n); the noise itself would only
        // turn tracers round at random): an up tracer leaves with probability (g - f - sigma) / g, a
        // down tracer with (f - g - sigma) / (1 - g).
        const double here = double(std::max<std::int32_t>(1, count[c]));
        const double g = double(upCount_[c]) / here;
        const double sigma = std::sqrt(f * (1.0 - f) / here);
        if (s && g - f > sigma && u * g < g - f - sigma) s = 0, ++switches;
        else if (!s && f - g > sigma && u * (1.0 - g) < f - g - sigma) s = 1, ++switches;
      }
      // What the stream does over the step, less what u_P^rec does: the kernel samples u_P^rec where
      // the stream's path has its midpoint (or at the start, with Euler), near where it is sampled here.
      const Eigen::Vector3d p = ctx.cloud.position(std::size_t(i));
      const Eigen::Vector3d move = streamDisplacement(ctx.grid, p, ctx.dt, s, rng, switches);
      const Eigen::Vector3d offset = move / ctx.dt - interpolate(locator, meanField_.data(), p + halfShare * move);
      ox[i] = float(offset.x()), oy[i] = float(offset.y()), oz[i] = float(offset.z());
      upTracers += s;
    }
    initialised_ = true;
    if (ctx.collecting()) {
      switches_ += switches;
      upShareSum_ += double(upTracers) / double(std::max<std::int64_t>(1, n));
      ++collected_;
    }
  }

  void writeResults(const TracerContext& ctx, h5::File&, nlohmann::json& summary) const override {
    const double seconds = double(collected_) * ctx.dt;
    const double n = double(std::max<std::size_t>(1, ctx.cloud.size()));
    summary["velocity_streams"] = {
        {"up_share_mean", collected_ > 0 ? upShareSum_ / double(collected_) : 0.0},
        {"switches_per_tracer_per_s", seconds > 0.0 ? double(switches_) / n / seconds : 0.0}};
  }

  void permuteTracers(TracerContext&, const std::vector<std::int32_t>& from) override { applyPermutation(up_, from); }

  void saveState(h5::File& f, const std::string& g) const override {
    f.write(g + "/up", std::vector<std::int64_t>(up_.begin(), up_.end()));
    f.write(g + "/counters", std::vector<std::int64_t>{initialised_, switches_, collected_});
    f.write(g + "/up_share_sum", std::vector<double>{upShareSum_});
  }
  void loadState(const h5::File& f, const std::string& g) override {
    const auto up = f.readInt64s(g + "/up");
    if (up.size() != up_.size()) throw InputError(f.path(), g + "/up", "does not hold one stream per tracer");
    for (std::size_t i = 0; i < up.size(); ++i) up_[i] = std::int8_t(up[i] != 0);
    const auto c = f.readInt64s(g + "/counters");
    initialised_ = c.at(0) != 0, switches_ = c.at(1), collected_ = c.at(2);
    upShareSum_ = f.readDoubles(g + "/up_share_sum").at(0);
  }

 private:
  /// The step's blended cell values: the up share, and u_up, u_down and u_P^rec (3 floats per cell).
  void buildStepFields(const TracerContext& ctx) {
    const FieldFrame& a = *ctx.frame;
    const FieldFrame* b = ctx.nextFrame.get();
    const double w = b ? ctx.blend : 0.0;
    const std::int64_t cells = ctx.grid.cellCount();
    upShare_.resize(std::size_t(cells));
    upField_.resize(3 * std::size_t(cells)), downField_.resize(upField_.size()), meanField_.resize(upField_.size());
    auto blend = [&](const std::vector<float> FieldFrame::*field, std::vector<float>& out) {
      const float* va = (a.*field).data();
      const float* vb = b ? (b->*field).data() : nullptr;
      const std::size_t size = out.size();
#pragma omp parallel for schedule(static) if (cells > kParallelThreshold)
      for (std::size_t k = 0; k < size; ++k) {
        out[k] = vb ? float(double(va[k]) + w * (double(vb[k]) - double(va[k]))) : va[k];
      }
    };
    blend(&FieldFrame::up_fraction, upShare_);
    blend(&FieldFrame::u_p_up, upField_);
    blend(&FieldFrame::u_p_down, downField_);
    blend(&FieldFrame::u_p, meanField_);
    alpha_.resize(std::size_t(cells));
    blend(&FieldFrame::alpha_p, alpha_);
    faceFluxes(ctx, upField_, true, upFaces_, upToDown_);
    faceFluxes(ctx, downField_, false, downFaces_, downToUp_);
  }

  /// One stream's face velocities and conversion per cell. The stream's volume flux density is
  /// q = alpha_P share u_stream per cell; a face carries the geometric mean of its two cells' q along
  /// its axis when they point the same way, nothing otherwise and nothing through a wall. A tracer of the stream
  /// in cell c moves, along each axis, with the velocity interpolated linearly between the two faces'
  /// flux over the stream's volume fraction in c (Pollock's scheme of groundwater particle tracking): it
  /// crosses a face only as fast as the face's flux allows, so a stream that ends inside a cell (the top
  /// of a fountain) keeps its tracers in that cell, where it converges. The convergence, the flux in
  /// beyond the flux out over the stream's volume, is the rate at which its tracers pass to the other
  /// stream there [1/s] (`out`).
  void faceFluxes(const TracerContext& ctx, const std::vector<float>& stream, bool up, std::vector<float>& faces,
                  std::vector<float>& out) const {
    const CartesianGrid& grid = ctx.grid;
    const std::int64_t cells = grid.cellCount();
    out.resize(std::size_t(cells));
    faces.resize(6 * std::size_t(cells));
    const auto& fluid = ctx.database->fluidFraction();
    auto shareOf = [&](std::size_t c) { return up ? double(upShare_[c]) : 1.0 - double(upShare_[c]); };
    auto flux = [&](std::size_t c, int d) { return double(alpha_[c]) * shareOf(c) * double(stream[3 * c + std::size_t(d)]); };
    const double area[3] = {grid.spacing.y() * grid.spacing.z(), grid.spacing.x() * grid.spacing.z(),
                            grid.spacing.x() * grid.spacing.y()};
#pragma omp parallel for schedule(static) if (cells > kParallelThreshold)
    for (std::int64_t c = 0; c < cells; ++c) {
      const std::size_t i = std::size_t(c);
      const double open = ctx.openVolume[i];
      const double volumeFraction = double(alpha_[i]) * shareOf(i);
      float* f = faces.data() + 6 * i;
      if (!(open > 0.0) || !(volumeFraction > 0.0)) {
        for (int k = 0; k < 6; ++k) f[k] = 0.0f;
        out[i] = 0.0f;
        continue;
      }
      const auto ijk = grid.cellIjk(c);
      double outflow = 0.0;  // [m3/s]
      for (int d = 0; d < 3; ++d) {
        const double qc = flux(i, d);
        for (int side = 0; side < 2; ++side) {
          auto n = ijk;
          n[std::size_t(d)] += side == 0 ? -1 : 1;
          double face = 0.0, a = 0.0;  // flux density in +d through the face, and its open area
          if (n[std::size_t(d)] >= 0 && n[std::size_t(d)] < grid.shape[d]) {
            const std::size_t e = std::size_t(grid.flatIndex(n[0], n[1], n[2]));
            if (fluid[e] > 0.0f) {
              const double qe = flux(e, d);
              // The geometric mean when both point the same way: small where either is (a stream that
              // ends), and less biased by noise than the smaller of the two (which made streams slow).
              face = qc * qe > 0.0 ? std::copysign(std::sqrt(qc * qe), qc) : 0.0;
              // As open as the cell itself: a cut cell's faces are not where its walls are (the kernel
              // keeps tracers off the exact walls), and the open share of a face between cut cells
              // stopped streams sliding along a slanted wall.
              a = area[d] * double(fluid[i]);
            }
          }
          // The velocity at the face: the flux over the stream's volume fraction.
          f[2 * d + side] = float(face / volumeFraction);
          outflow += (side == 0 ? -1.0 : 1.0) * face * a;
        }
      }
      const double rate = outflow / (open * volumeFraction);  // [1/s]
      out[i] = float(std::max(0.0, -rate));                   // inflow beyond outflow: the stream ends here
    }
  }

  /// Where a tracer goes in `time` from p, and in which stream it ends (`up`, updated): cell by cell
  /// through its stream's velocity, linear per axis between the faces of each cell (faceFluxes()),
  /// integrated exactly (Pollock): along an axis v = v0 + g x gives v(t) = v e^(g t), and the time to a
  /// face follows in closed form; a face whose velocity points back into the cell (or is zero) is never
  /// crossed. In each cell the tracer passes to the other stream after an exponential time of the
  /// cell's conversion rate (memoryless, so drawn afresh in every cell): continuous in time, so a
  /// stream that ends in a cell hands its tracers over where they are, at any particle Courant number.
  Eigen::Vector3d streamDisplacement(const CartesianGrid& grid, const Eigen::Vector3d& start, double time,
                                     std::int8_t& up, CounterRng& rng, std::int64_t& switches) const {
    Eigen::Vector3d p = start;
    constexpr int kMaxEvents = 64;  // cells entered and conversions within one step
    for (int event = 0; event < kMaxEvents && time > 0.0; ++event) {
      const auto ijk = grid.cellOf(p);
      const std::size_t c = std::size_t(grid.flatIndex(ijk[0], ijk[1], ijk[2]));
      const float* f = (up ? upFaces_ : downFaces_).data() + 6 * c;
      const double rate = up ? upToDown_[c] : downToUp_[c];
      const double conversion = rate > 0.0 ? -std::log1p(-rng.uniform()) / rate : time;
      double x[3], v[3], g[3], until = std::min(time, conversion);
      int exitAxis = -1, exitSide = 0;
      for (int d = 0; d < 3; ++d) {
        const double h = grid.spacing[d], lo = grid.origin[d] + h * ijk[std::size_t(d)];
        x[d] = std::clamp(p[d] - lo, 0.0, h);
        const double v0 = f[2 * d], v1 = f[2 * d + 1];
        g[d] = (v1 - v0) / h;
        v[d] = v0 + g[d] * x[d];
        const double faceVelocity = v[d] > 0.0 ? v1 : v0;
        if (v[d] == 0.0 || faceVelocity * v[d] <= 0.0) continue;  // at rest, or stagnating before the face
        const double gap = v[d] > 0.0 ? h - x[d] : -x[d];
        const double t = std::abs(g[d] * gap) < 1e-9 * std::abs(v[d]) ? gap / v[d] : std::log(faceVelocity / v[d]) / g[d];
        if (t < until) until = std::max(0.0, t), exitAxis = d, exitSide = v[d] > 0.0 ? 1 : -1;
      }
      for (int d = 0; d < 3; ++d) {
        const double h = grid.spacing[d], lo = grid.origin[d] + h * ijk[std::size_t(d)];
        double xn;
        if (d == exitAxis) {
          xn = exitSide > 0 ? h * (1.0 + 1e-9) : -h * 1e-9;  // just across the face: the next cell
        } else if (std::abs(g[d] * until) < 1e-9) {
          xn = x[d] + v[d] * until;
        } else {
          xn = (v[d] * std::exp(g[d] * until) - (v[d] - g[d] * x[d])) / g[d];
        }
        p[d] = lo + xn;
      }
      time -= until;
      if (exitAxis < 0) {
        if (conversion <= until && time > 0.0) {
          up = std::int8_t(1 - up), ++switches;
          continue;
        }
        break;
      }
      if (grid.cellOf(p) == ijk) break;  // the grid's edge (the face had no flux): stay
    }
    return p - start;
  }

  /// Trilinear interpolation of a field of 3 floats per cell at p (FrameSampler's rule).
  static Eigen::Vector3d interpolate(const TrilinearLocator& locator, const float* field, const Eigen::Vector3d& p) {
    const TrilinearStencil st = locator.locate(p);
    Eigen::Vector3d corners[8];
    for (int k = 0; k < 8; ++k) {
      const float* v = field + 3 * (st.base + locator.offset(k));
      corners[k] = Eigen::Vector3d(v[0], v[1], v[2]);
    }
    return trilinear(corners, st.f);
  }

  bool midpoint_ = true;                ///< the kernel's integrator (rcfd.integrator)
  std::vector<float> upShare_, upField_, downField_, meanField_, alpha_;  ///< the step's blended cell values
  std::vector<float> upToDown_, downToUp_;  ///< per cell: rate of passing to the other stream [1/s]
  std::vector<float> upFaces_, downFaces_;  ///< per cell: the streams' velocities at the six faces (faceFluxes())
  std::vector<std::int8_t> up_;         ///< per tracer index: 1 in the up stream, 0 in the down stream
  std::vector<std::int32_t> upCount_;   ///< per cell: tracers of the up stream at the start of the step
  bool initialised_ = false;            ///< streams drawn (at the first step)
  std::int64_t switches_ = 0;           ///< stream changes in the collecting steps
  std::int64_t collected_ = 0;          ///< collecting steps
  double upShareSum_ = 0.0;             ///< sum over collecting steps of the share of up tracers
};

const bool registered = TracerEffectRegistry::add(
    "velocity_streams", {"transport", "tracer_volume_fraction"}, 11,
    "two-stream velocity: tracers move with the mean velocity of the up- or down-moving particles of their cell, "
    "in the database's shares (needs the frames' velocity spread)",
    [](TracerContext& c) { return std::make_unique<VelocityStreamsEffect>(c); }, true);

}  // namespace
}  // namespace rcfd
