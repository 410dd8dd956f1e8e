// directed_relaxation: a deterministic velocity that moves tracers down the gradient of their excess
// over alpha_P^rec, the directed relaxation of the CFDEMcoupling-PFM recurrence code (Lichtenegger's
// directedDiffusiveRelaxation) instead of Eq. (10)'s random walk. Per step, with e = alpha_P,tracers -
// alpha_P^rec per open cell:
//   1. one implicit diffusion step of the excess, (I - D0 dt L) w = e (L: the 7-point Laplacian over
//      the open cells, no flux into closed ones or across a draft plate), solved by conjugate
//      gradients from the last step's w;
//   2. through every open face the diffusive flux of particle volume -D0 grad w, carried by the
//      tracers of the cell it leaves: u_relax = flux / alpha_P,tracers, capped at rcfd.u_fluc_max and
//      at half a cell per step;
//   3. every tracer gets the face velocities of its cell interpolated to its position, added to
//      Eq. (9) over the step (TracerContext::streamVelocity, after velocity_streams when both are
//      listed).
// Eq. (10) only pushes tracers out of over-packed cells in random directions; the directed flux also
// fills under-packed ones (the dilute spout, which tracers under-populate) and does not spread
// tracers that are where they should be. The implicit step keeps it stable for any D0 dt / h^2 and
// smooths the counting noise the excess carries. Deterministic (the solver's sums run in one order)
// and free when D0 = 0.
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <memory>

#include "geometry/ThinWalls.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace {

/// Relative residual of the implicit step: far below the counting noise the excess carries.
constexpr double kSolverTolerance = 1e-4;
constexpr int kSolverIterations = 500;

class DirectedRelaxationEffect final : public TracerEffect {
 public:
  explicit DirectedRelaxationEffect(TracerContext& ctx)
      : d0_(ctx.scene.rcfd.d0), cap_(ctx.scene.rcfd.u_fluc_max), tracers_(ctx.cloud.size()) {
    const std::size_t n = tracers_;
    owner_ = ctx.streamVelocity[0].size() != n;  // velocity_streams, listed too, sets it before us
    if (owner_) {
      for (auto& v : ctx.streamVelocity) v.assign(n, 0.0f);
    }
    if (!(d0_ > 0.0)) return;
    baffles_ = thinWallBaffles(ctx.apparatus, ctx.grid);
    const CartesianGrid& grid = ctx.grid;
    const std::int64_t cells = grid.cellCount();
    row_.assign(std::size_t(cells), -1);
    for (std::int64_t c = 0; c < cells; ++c) {
      if (ctx.openVolume[std::size_t(c)] > 0.0) {
        row_[std::size_t(c)] = std::int32_t(open_.size());
        open_.push_back(std::int32_t(c));
      }
    }
    const double beta[3] = {d0_ * ctx.dt / (grid.spacing.x() * grid.spacing.x()),
                            d0_ * ctx.dt / (grid.spacing.y() * grid.spacing.y()),
                            d0_ * ctx.dt / (grid.spacing.z() * grid.spacing.z())};
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(7 * open_.size());
    upperNeighbour_.assign(3 * open_.size(), -1);
    for (std::size_t r = 0; r < open_.size(); ++r) {
      double diagonal = 1.0;
      forEachNeighbour(ctx, open_[r], [&](int d, int side, std::int32_t other) {
        entries.emplace_back(int(r), row_[std::size_t(other)], -beta[d]);
        diagonal += beta[d];
        if (side > 0) upperNeighbour_[3 * r + std::size_t(d)] = row_[std::size_t(other)];
      });
      entries.emplace_back(int(r), int(r), diagonal);
    }
    matrix_.resize(int(open_.size()), int(open_.size()));
    matrix_.setFromTriplets(entries.begin(), entries.end());
    solver_.setTolerance(kSolverTolerance);
    solver_.setMaxIterations(kSolverIterations);
    solver_.compute(matrix_);
    excess_.setZero(Eigen::Index(open_.size()));
    w_.setZero(Eigen::Index(open_.size()));
    faceVelocity_.assign(6 * std::size_t(cells), 0.0f);
    cellLower_.resize(3 * std::size_t(cells));
    for (std::int64_t c = 0; c < cells; ++c) {
      const auto ijk = grid.cellIjk(c);
      for (int d = 0; d < 3; ++d)
        cellLower_[3 * std::size_t(c) + std::size_t(d)] = grid.origin[d] + grid.spacing[d] * ijk[std::size_t(d)];
    }
  }

  std::size_t allocatedBytes() const override {
    return (owner_ ? 3 * tracers_ * sizeof(float) : 0) + row_.capacity() * sizeof(std::int32_t) +
           (open_.capacity() + upperNeighbour_.capacity()) * sizeof(std::int32_t) + std::size_t(matrix_.nonZeros()) * (sizeof(double) + sizeof(int)) +
           std::size_t(excess_.size() + w_.size()) * sizeof(double) + faceVelocity_.capacity() * sizeof(float) + cellLower_.capacity() * sizeof(double);
  }

  void beforeMove(TracerContext& ctx) override {
    const std::size_t n = ctx.cloud.size();
    float* out[3] = {ctx.streamVelocity[0].data(), ctx.streamVelocity[1].data(), ctx.streamVelocity[2].data()};
    if (!(d0_ > 0.0)) {
      if (owner_) {
        for (auto* o : out) std::fill(o, o + n, 0.0f);
      }
      return;
    }
    solveExcess(ctx);
    faceVelocities(ctx);
    // Each tracer: per direction, the velocities of its cell's two faces interpolated linearly to its
    // position in the cell (the field whose divergence is the flux's).
    const std::int32_t* cellOf = ctx.tracerCell.data();
    const float* faces = faceVelocity_.data();
    const double* lowerCorner = cellLower_.data();
    const double inverseSpacing[3] = {1.0 / ctx.grid.spacing.x(), 1.0 / ctx.grid.spacing.y(), 1.0 / ctx.grid.spacing.z()};
    const double* position[3] = {ctx.cloud.x.data(), ctx.cloud.y.data(), ctx.cloud.z.data()};
#pragma omp parallel for schedule(static) if (std::int64_t(n) > kParallelThreshold)
    for (std::int64_t i = 0; i < std::int64_t(n); ++i) {
      const std::size_t c = std::size_t(cellOf[i]);
      for (int d = 0; d < 3; ++d) {
        const double s =
            std::clamp((position[d][i] - lowerCorner[3 * c + std::size_t(d)]) * inverseSpacing[d], 0.0, 1.0);
        const double u = (1.0 - s) * double(faces[6 * c + 2 * std::size_t(d)]) + s * double(faces[6 * c + 2 * std::size_t(d) + 1]);
        out[d][i] = owner_ ? float(u) : out[d][i] + float(u);
      }
    }
  }

  void saveState(h5::File& f, const std::string& g) const override {
    if (w_.size() > 0) f.write(g + "/w", std::vector<double>(w_.data(), w_.data() + w_.size()));
  }
  void loadState(const h5::File& f, const std::string& g) override {
    if (w_.size() == 0) return;
    const auto w = f.readDoubles(g + "/w");
    if (w.size() == std::size_t(w_.size())) std::copy(w.begin(), w.end(), w_.data());
  }

 private:
  /// Calls f(dimension, side, neighbour) for each open neighbour of cell c that no plate separates
  /// from it (no flux pushes tracers against a plate they cannot pass): those the CFD-DEM's mapping
  /// and smoothing keep apart (plateSeparates), so the relaxation moves the particle volume of a cell
  /// column holding a plate on the side the frames put it.
  template <class F>
  void forEachNeighbour(const TracerContext& ctx, std::int32_t c, F&& f) const {
    const CartesianGrid& grid = ctx.grid;
    const auto ijk = grid.cellIjk(c);
    for (int d = 0; d < 3; ++d) {
      for (int side : {-1, 1}) {
        auto nb = ijk;
        nb[std::size_t(d)] += side;
        if (nb[std::size_t(d)] < 0 || nb[std::size_t(d)] >= grid.shape[std::size_t(d)]) continue;
        const auto other = std::int32_t(grid.flatIndex(nb[0], nb[1], nb[2]));
        if (row_[std::size_t(other)] < 0) continue;
        if (plateSeparates(ctx.apparatus, grid, baffles_, ijk, d, side)) continue;
        f(d, side, other);
      }
    }
  }

  /// e = alpha_P of the tracers - alpha_P^rec of the step, then one implicit diffusion step of it.
  void solveExcess(TracerContext& ctx) {
    const FieldFrame& a = *ctx.frame;
    const FieldFrame* b = ctx.nextFrame.get();
    const double blend = ctx.blend;
    for (std::size_t r = 0; r < open_.size(); ++r) {
      const std::size_t c = std::size_t(open_[r]);
      const double rec = b ? double(a.alpha_p[c]) + blend * (double(b->alpha_p[c]) - double(a.alpha_p[c]))
                           : double(a.alpha_p[c]);
      excess_[Eigen::Index(r)] = double(ctx.tracerAlpha[c]) - rec;
    }
    w_ = solver_.solveWithGuess(excess_, w_);
  }

  /// The face velocities of the relaxation flux: through each open face between cells i and j the
  /// flux of particle volume F = -D0 (w_j - w_i) / h of the implicit step, carried by the tracers of
  /// the donor cell (the one it leaves), u = F / alpha_P,donor; 0 where the donor holds no tracer, and
  /// capped at rcfd.u_fluc_max and at half a cell per step. Face-based, a checkerboard excess (which a
  /// cell-centred gradient does not see) is damped like any other.
  void faceVelocities(const TracerContext& ctx) {
    const CartesianGrid& grid = ctx.grid;
    std::fill(faceVelocity_.begin(), faceVelocity_.end(), 0.0f);
    const std::int64_t rows = std::int64_t(open_.size());
    // Each face is written by its lower cell only: rows are independent. A row is a few operations, so
    // only paper-size grids pay for a parallel region (on a loaded machine its barrier costs more than
    // the quick slice's whole loop).
#pragma omp parallel for schedule(static) if (rows > 8 * kParallelThreshold)
    for (std::int64_t rr = 0; rr < rows; ++rr) {
      const std::size_t r = std::size_t(rr);
      const std::size_t c = std::size_t(open_[r]);
      const double here = w_[Eigen::Index(r)];
      for (int d = 0; d < 3; ++d) {  // each face once, from its lower cell
        const std::int32_t upper = upperNeighbour_[3 * r + std::size_t(d)];
        if (upper < 0) continue;
        const std::size_t other = std::size_t(open_[std::size_t(upper)]);
        const double h = grid.spacing[d];
        const double flux = -d0_ * (w_[Eigen::Index(upper)] - here) / h;  // + along d
        const double donor = double(ctx.tracerAlpha[flux > 0.0 ? c : other]);
        double u = donor > 0.0 ? flux / donor : 0.0;
        const double bound = std::min(cap_, 0.5 * h / ctx.dt);
        u = std::clamp(u, -bound, bound);
        faceVelocity_[6 * c + 2 * std::size_t(d) + 1] = float(u);
        faceVelocity_[6 * other + 2 * std::size_t(d)] = float(u);
      }
    }
  }

  double d0_, cap_;
  bool owner_ = false;
  std::size_t tracers_ = 0;
  BaffleFaces baffles_;              ///< the plates snapped to grid faces (geometry/ThinWalls.hpp)
  std::vector<std::int32_t> row_;   ///< per cell: its row among the open cells, or -1
  std::vector<std::int32_t> open_;  ///< per row: its cell
  std::vector<std::int32_t> upperNeighbour_;  ///< per row and axis: the row of the open cell above, or -1
  // The self-adjoint product of the lower triangle, on one thread (Eigen does not parallelise in
  // rcfd: EIGEN_DONT_PARALLELIZE): a parallel region per iteration would cost more than the small solve.
  Eigen::SparseMatrix<double> matrix_;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower> solver_;
  Eigen::VectorXd excess_, w_;
  std::vector<float> faceVelocity_;  ///< per cell: u_relax at its faces (x-, x+, y-, y+, z-, z+) [m/s]
  std::vector<double> cellLower_;    ///< per cell: its lower corner (x, y, z) [m]
};

const bool registered = TracerEffectRegistry::add(
    "directed_relaxation", {"transport", "tracer_volume_fraction"}, 12,
    "directed relaxation: tracers move down the gradient of their excess over alpha_P^rec (one implicit "
    "diffusion step with D0 per step; CFDEMcoupling-PFM's directedDiffusiveRelaxation), filling "
    "under-packed cells as well as emptying over-packed ones",
    [](TracerContext& c) { return std::make_unique<DirectedRelaxationEffect>(c); });

}  // namespace
}  // namespace rcfd
