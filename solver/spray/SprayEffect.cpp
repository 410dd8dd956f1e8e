// spray: droplet parcels injected at the nozzle into the spray cone and carried by u_G^rec (their
// relaxation time is below 5 ms, the paper). A parcel that reaches a wall, plate or the inlet, or leaves
// through the outlet, is overspray. With `deposition`, parcels deposit along every sub-step of their
// flight (ParcelDeposition), and the books of those deposits are kept here, in block order.
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "geometry/WallClearance.hpp"
#include "spray/SprayLaunch.hpp"
#include "spray/SprayState.hpp"
#include "tracers/BlockSampling.hpp"
#include "tracers/CellIndex.hpp"
#include "tracers/CounterRng.hpp"
#include "tracers/StepField.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace {

class SprayEffect final : public TracerEffect {
 public:
  explicit SprayEffect(TracerContext& ctx) : spec_(ctx.scene.spray) {
    ctx.spray = std::make_shared<SprayState>();
    state_ = ctx.spray;
    auto& s = *ctx.spray;
    const double d = spec_.droplet_diameter;
    s.dropletMass = spec_.droplet_density * std::numbers::pi / 6.0 * d * d * d;
    s.dropletsPerParcel = spec_.mass_rate / spec_.parcels_per_s / s.dropletMass;
    cosHalfAngle_ = std::cos(spec_.cone_half_angle_deg * std::numbers::pi / 180.0);
    launchSpread_ = ctx.grid.spacing.minCoeff();
    minSpacing_ = ctx.grid.spacing.minCoeff();
    // Per cell, a move shorter than this cannot reach a boundary; most parcel sub-steps then skip the
    // exact test, with the same result.
    clearance_ = cellWallClearance(ctx.apparatus, ctx.grid,
                                   0.5 * ctx.grid.spacing.norm() + 2.0 * ctx.apparatus.boundaryTolerance());
  }

  std::size_t allocatedBytes() const override {
    std::size_t deposits = blockDeposits_.capacity() * sizeof(blockDeposits_[0]);
    for (const auto& d : blockDeposits_) deposits += d.capacity() * sizeof(StrippedDroplets);
    return sizeof(SprayState) + clearance_.capacity() * sizeof(float) + exit_.capacity() + deposits;
  }

  bool afterMoveBesideMotion() const override { return true; }
  void afterMove(TracerContext& ctx) override {
    auto& s = *ctx.spray;
    moveParcels(ctx, s);
    inject(ctx, s);
  }

  void writeResults(const TracerContext&, h5::File& out, nlohmann::json& summary) const override {
    const auto& s = *state_;
    const auto& b = s.balance;
    const double m = s.dropletMass;
    const double airborne = s.airborne();
    const double overspray = b.oversprayWall + b.oversprayOutlet;
    // residual: parcels removed with fewer than one droplet left (docs/contracts.md, "Mass balance");
    // closure_error: what the books fail to account for (round-off only).
    const double closure = b.injected - (b.deposited + airborne + overspray + b.residual);
    double pending = 0.0;
    for (double p : s.cellPending) pending += p;
    summary["mass_balance"] = {{"injected_kg", b.injected * m},
                               {"deposited_kg", b.deposited * m},
                               {"airborne_kg", airborne * m},
                               {"overspray_kg", overspray * m},
                               {"overspray_wall_kg", b.oversprayWall * m},
                               {"overspray_outlet_kg", b.oversprayOutlet * m},
                               {"on_tracers_kg", s.assigned * m},
                               {"pending_in_cells_kg", pending * m},
                               {"residual_kg", b.residual * m},
                               {"closure_error_kg", closure * m}};
    summary["overspray_fraction"] = b.injected > 0.0 ? overspray / b.injected : 0.0;
    summary["parcels"] = {{"injected", s.injectedParcels},
                          {"airborne", s.parcels.size()},
                          {"droplets_per_parcel", s.dropletsPerParcel}};
    out.write("/spray/parcels/x", s.parcels.x);
    out.write("/spray/parcels/y", s.parcels.y);
    out.write("/spray/parcels/z", s.parcels.z);
    out.write("/spray/parcels/droplets", s.parcels.droplets);
    out.write("/spray/balance_droplets",
              std::vector<double>{b.injected, b.deposited, airborne, b.oversprayWall, b.oversprayOutlet, b.residual});
  }

  void saveState(h5::File& f, const std::string& g) const override {
    const auto& s = *state_;
    f.write(g + "/x", s.parcels.x);
    f.write(g + "/y", s.parcels.y);
    f.write(g + "/z", s.parcels.z);
    f.write(g + "/droplets", s.parcels.droplets);
    f.write(g + "/id", s.parcels.id);
    const auto& b = s.balance;
    f.write(g + "/balance", std::vector<double>{b.injected, b.deposited, b.oversprayWall, b.oversprayOutlet, b.residual});
    f.write(g + "/injected_parcels", std::vector<std::int64_t>{s.injectedParcels});
  }
  void loadState(const h5::File& f, const std::string& g) override {
    auto& s = *state_;
    s.parcels.x = f.readDoubles(g + "/x");
    s.parcels.y = f.readDoubles(g + "/y");
    s.parcels.z = f.readDoubles(g + "/z");
    s.parcels.droplets = f.readDoubles(g + "/droplets");
    s.parcels.id = f.readInt64s(g + "/id");
    const auto b = f.readDoubles(g + "/balance");
    s.balance = {b.at(0), b.at(1), b.at(2), b.at(3), b.at(4)};
    s.injectedParcels = f.readInt64s(g + "/injected_parcels").at(0);
  }

 private:
  /// Parcels injected in step s: floor((s+1) R dt) - floor(s R dt), so the count never drifts.
  std::int64_t parcelsDue(std::int64_t step, double dt) const {
    const long double perStep = (long double)spec_.parcels_per_s * (long double)dt;
    return std::int64_t(std::floor((step + 1) * perStep + 1e-9L)) - std::int64_t(std::floor(step * perStep + 1e-9L));
  }

  void inject(TracerContext& ctx, SprayState& s) const {
    const std::int64_t n = parcelsDue(ctx.step, ctx.dt);
    for (std::int64_t j = 0; j < n; ++j) {
      const std::int64_t index = s.injectedParcels + j;
      CounterRng rng(ctx.seed, RngPurpose::SprayInjection, std::uint64_t(index), 0);
      const double u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
      const Eigen::Vector3d p = sprayLaunchPoint(spec_, cosHalfAngle_, launchSpread_, u1, u2, u3);
      if (ctx.apparatus.signedDistance(p) > 0.0) {
        s.parcels.push(p, s.dropletsPerParcel, index);
      } else {
        s.balance.oversprayWall += s.dropletsPerParcel;  // the cone starts in a wall: all overspray
      }
    }
    s.injectedParcels += n;
    // From the integer count, not a running sum: exact to one rounding however long the run.
    s.balance.injected = double(s.injectedParcels) * s.dropletsPerParcel;
  }

  void moveParcels(TracerContext& ctx, SprayState& s) {
    auto& pc = s.parcels;
    const std::int64_t n = std::int64_t(pc.size());
    if (s.deposition) s.clearStepDeposits();
    if (n == 0) return;
    if (s.deposition) s.deposition->beginStep(ctx);
    exit_.assign(std::size_t(n), 0);  // 0 airborne, 1 wall, 2 outlet
    const FrameSampler frames = ctx.sampler();
    // u_G^rec of the step as a step field: parcels read its corners with the tracer kernel's block
    // functions (float trilinear, block::interpolateCorners) instead of blending and converting 8
    // corners in double per sub-step. On a frame, the frame's own array: ~1,300 samples per step do not
    // pay for a copy of all 74k cells.
    const StepVelocityField& gas = ctx.stepVelocity(true, StepFieldLayout::Any);
    BlockMove move{gas.floats(),  frames.locator().constants(), {}, CellIndexer(ctx.grid), ctx.dt, minSpacing_,
                   s.deposition};
    move.corners.set(frames.locator().offsets32(), gas.stride());
    const std::int64_t blocks = (n + block::kBlock - 1) / block::kBlock;
    if (blockDeposits_.size() < std::size_t(blocks)) blockDeposits_.resize(std::size_t(blocks));
    // Blocks start at multiples of kBlock and parcels are independent: the same for any thread count.
#pragma omp parallel for schedule(dynamic, 1) if (n > kParallelThreshold)  // sub-steps vary: dynamic
    for (std::int64_t b = 0; b < blocks; ++b) {
      const std::int64_t j0 = b * block::kBlock;
      auto& deposits = blockDeposits_[std::size_t(b)];
      deposits.clear();
      moveBlock(ctx, move, pc, j0, int(std::min<std::int64_t>(block::kBlock, n - j0)), deposits);
    }
    // Serial, in block order: the books and the compaction are the same for any thread count.
    for (std::int64_t b = 0; b < blocks; ++b) {
      for (const StrippedDroplets& d : blockDeposits_[std::size_t(b)]) s.bookDeposit(d.cell, d.droplets);
    }
    std::size_t keep = 0;
    for (std::size_t j = 0; j < std::size_t(n); ++j) {
      if (exit_[j] == 1) s.balance.oversprayWall += pc.droplets[j];
      if (exit_[j] == 2) s.balance.oversprayOutlet += pc.droplets[j];
      if (exit_[j] != 0) continue;
      if (pc.droplets[j] < kMinDropletsPerParcel) {
        s.balance.residual += pc.droplets[j];
        continue;
      }
      if (keep != j) {
        pc.x[keep] = pc.x[j], pc.y[keep] = pc.y[j], pc.z[keep] = pc.z[j];
        pc.droplets[keep] = pc.droplets[j], pc.id[keep] = pc.id[j];
      }
      ++keep;
    }
    pc.x.resize(keep), pc.y.resize(keep), pc.z.resize(keep), pc.droplets.resize(keep), pc.id.resize(keep);
  }

  /// What every block of parcels reads in a step.
  struct BlockMove {
    const float* field;                     ///< u_G^rec of the step, StepVelocityField::stride() floats per cell
    TrilinearLocator::Constants locator;
    block::CornerOffsets corners;
    CellIndexer indexer;
    double dt;
    double spacing;                         ///< smallest cell spacing [m]
    const ParcelDeposition* deposition;     ///< null: parcels only fly
  };

  /// Droplets a parcel left in a cell over one sub-step.
  struct StrippedDroplets {
    std::int32_t cell;
    double droplets;
  };

  /// Lanes of a block of parcels still moving, compacted after every sub-step round.
  struct ParcelLanes {
    alignas(64) double x[block::kBlock], y[block::kBlock], z[block::kBlock];
    alignas(64) double ux[block::kBlock], uy[block::kBlock], uz[block::kBlock];
    alignas(64) double h[block::kBlock];
    alignas(64) std::int32_t left[block::kBlock], cell[block::kBlock], parcel[block::kBlock];
  };

  /// u_G^rec at the first `count` lanes' positions.
  static void sampleLanes(const BlockMove& bm, ParcelLanes& L, int count) {
    alignas(64) static constexpr double kZero[block::kBlock] = {};
    block::BlockStencils stencils;
    block::locateBlock(bm.locator, count, L.x, L.y, L.z, stencils);
    block::sampleBlock(bm.field, bm.corners, stencils, count, kZero, kZero, kZero, L.ux, L.uy, L.uz);
  }

  /// Parcels j0 .. j0 + count - 1 through the step: sub-steps so that none moves farther than one
  /// cell at its start velocity (particle Courant number <= 1, at most 64), u_G^rec sampled at every
  /// sub-step's start; a sub-step that may reach a boundary gets the exact segment test, and a hit
  /// ends the parcel there (overspray). Over every sub-step (up to the hit) the parcel deposits the
  /// fraction bm.deposition gives for its midpoint and duration, appended to `deposits` in the order
  /// taken. Rounds run on the lanes with sub-steps left, compacted.
  void moveBlock(const TracerContext& ctx, const BlockMove& bm, ParcelCloud& pc, std::int64_t j0, int count,
                 std::vector<StrippedDroplets>& deposits) {
    constexpr int kMaxParcelSubsteps = 64;
    ParcelLanes L;
    for (int k = 0; k < count; ++k) {
      const std::size_t j = std::size_t(j0 + k);
      L.x[k] = pc.x[j], L.y[k] = pc.y[j], L.z[k] = pc.z[j];
      L.parcel[k] = k;
    }
    sampleLanes(bm, L, count);
    for (int k = 0; k < count; ++k) {
      const double courant = Eigen::Vector3d(L.ux[k], L.uy[k], L.uz[k]).norm() * bm.dt / bm.spacing;
      const int nsub = courant < double(kMaxParcelSubsteps) ? std::max(1, int(std::ceil(courant)))
                                                            : kMaxParcelSubsteps;  // also for NaN
      L.h[k] = bm.dt / nsub;
      L.left[k] = nsub;
    }
    const float* clearance = clearance_.data();
    int active = count;
    while (active > 0) {
      bm.indexer.cellsOf(active, L.x, L.y, L.z, L.cell);
      alignas(64) std::int32_t fast[block::kBlock];
      // Moves shorter than their cell's clearance reach no boundary (compared squared: either answer
      // near the bound is safe, the exact test finds no hit for a move clear of every boundary).
#pragma omp simd
      for (int k = 0; k < active; ++k) {
        const double dx = L.h[k] * L.ux[k], dy = L.h[k] * L.uy[k], dz = L.h[k] * L.uz[k];
        const double c = double(clearance[L.cell[k]]);
        fast[k] = std::int32_t(c > 0.0) & std::int32_t(dx * dx + dy * dy + dz * dz < c * c);
      }
      int kept = 0;
      for (int k = 0; k < active; ++k) {
        const Eigen::Vector3d p(L.x[k], L.y[k], L.z[k]);
        const Eigen::Vector3d end = p + L.h[k] * Eigen::Vector3d(L.ux[k], L.uy[k], L.uz[k]);
        Eigen::Vector3d at = end;
        bool done = --L.left[k] == 0;
        double seconds = L.h[k];
        if (!fast[k]) {
          if (const auto hit = ctx.apparatus.firstIntersection(p, end)) {
            exit_[std::size_t(j0 + L.parcel[k])] = hit->kind == BoundaryKind::Outlet ? 2 : 1;
            const double full = (end - p).norm();
            seconds = full > 0.0 ? L.h[k] * std::min(1.0, (hit->point - p).norm() / full) : 0.0;
            at = hit->point;
            done = true;
          }
        }
        if (bm.deposition && seconds > 0.0) {
          const std::size_t j = std::size_t(j0 + L.parcel[k]);
          std::int32_t cell = -1;
          const double eta = bm.deposition->efficiency(0.5 * (p + at), seconds, cell);
          if (eta > 0.0) {
            const double stripped = pc.droplets[j] * eta;
            pc.droplets[j] -= stripped;
            deposits.push_back({cell, stripped});
          }
        }
        if (done) {
          const std::size_t j = std::size_t(j0 + L.parcel[k]);
          pc.x[j] = at.x(), pc.y[j] = at.y(), pc.z[j] = at.z();
          continue;
        }
        L.x[kept] = at.x(), L.y[kept] = at.y(), L.z[kept] = at.z();
        L.h[kept] = L.h[k], L.left[kept] = L.left[k], L.parcel[kept] = L.parcel[k];
        ++kept;
      }
      active = kept;
      if (active > 0) sampleLanes(bm, L, active);
    }
  }

  SpraySpec spec_;
  std::shared_ptr<SprayState> state_;
  double cosHalfAngle_ = 1.0;
  double launchSpread_ = 0.0;
  double minSpacing_ = 1.0;
  std::vector<float> clearance_;  ///< per cell: moves shorter than this hit no boundary [m]
  std::vector<std::int8_t> exit_; ///< per parcel of the step: 0 airborne, 1 wall, 2 outlet
  std::vector<std::vector<StrippedDroplets>> blockDeposits_;  ///< per block of parcels: its deposits this step
};

const bool registered = TracerEffectRegistry::add(
    "spray", {}, 50, "droplet parcels injected at the nozzle in the spray cone, carried by u_G^rec",
    [](TracerContext& c) { return std::make_unique<SprayEffect>(c); });

}  // namespace
}  // namespace rcfd
