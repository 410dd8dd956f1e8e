#pragma once
/// \file SprayState.hpp
/// Droplet parcels (structure of arrays) and the spray's books, shared by the spray-stage effects.
/// Droplet numbers are double: a parcel of ~25 droplets loses a fraction eta per step, and the mass
/// balance injected = deposited + airborne + overspray + residual must close to round-off.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace rcfd {

struct TracerContext;

/// Parcels with fewer droplets left are removed, their droplets booked as residual (N_D,min, the paper).
inline constexpr double kMinDropletsPerParcel = 1.0;

/// Eq. (11)-(14) over a piece of a parcel's path: provided by the `deposition` effect, which the
/// `spray` effect asks along every sub-step of every parcel (so a parcel that crosses several cells in
/// a step deposits in each, for the time it spends there, and one that reaches a wall deposits on the
/// way). Without `deposition`, parcels only fly.
class ParcelDeposition {
 public:
  virtual ~ParcelDeposition() = default;
  /// Once per step, before the parcels move, on the thread that moves them.
  virtual void beginStep(TracerContext& ctx) = 0;
  /// Fraction in [0, 1] of a parcel's droplets deposited while it spends `seconds` on the segment
  /// whose midpoint is `mid`; `cell` receives the cell they deposit in. Thread-safe.
  virtual double efficiency(const Eigen::Vector3d& mid, double seconds, std::int32_t& cell) const = 0;
};

struct ParcelCloud {
  std::vector<double> x, y, z;   ///< position [m]
  std::vector<double> droplets;  ///< droplets carried [-]
  std::vector<std::int64_t> id;  ///< injection index (stable across compaction)

  std::size_t size() const { return x.size(); }
  Eigen::Vector3d position(std::size_t i) const { return {x[i], y[i], z[i]}; }
  void push(const Eigen::Vector3d& p, double n, std::int64_t index) {
    x.push_back(p.x()), y.push_back(p.y()), z.push_back(p.z()), droplets.push_back(n), id.push_back(index);
  }
};

/// Where the injected droplets are, in droplets (multiply by dropletMass for kg).
struct SprayBalance {
  double injected = 0.0;
  double deposited = 0.0;        ///< on tracers (particles)
  double oversprayWall = 0.0;    ///< parcels that reached a wall, plate or the inlet
  double oversprayOutlet = 0.0;  ///< parcels that left through the outlet
  double residual = 0.0;         ///< parcels removed with fewer than one droplet left
};

struct SprayState {
  ParcelCloud parcels;
  SprayBalance balance;
  std::int64_t injectedParcels = 0;
  double dropletMass = 0.0;         ///< rho_D pi d_D^3 / 6 [kg]
  double dropletsPerParcel = 0.0;   ///< N_D at injection [-]

  /// Set by `deposition` (null: no deposition); the effect owns it and lives as long as the state.
  ParcelDeposition* deposition = nullptr;

  // Allocated by `deposition`:
  std::vector<double> cellDeposit;      ///< droplets stripped from parcels per cell in the current step
  std::vector<std::int32_t> depositCells;  ///< the cells where cellDeposit > 0 (the rest is 0), in first-deposit order
  std::vector<double> cellPending;      ///< stripped droplets not yet handed to a tracer (< 1 per cell)
  double assigned = 0.0;                ///< droplets handed to tracers (whole droplets)
  std::vector<double> tracerDroplets;   ///< whole droplets collected by each tracer (all its particles)

  /// Starts a step's deposits: the cells of the last step's are emptied (only they hold anything).
  void clearStepDeposits() {
    for (const std::int32_t c : depositCells) cellDeposit[std::size_t(c)] = 0.0;
    depositCells.clear();
  }
  /// Books `droplets` (> 0) stripped from a parcel in `cell`.
  void bookDeposit(std::int32_t cell, double droplets) {
    if (cellDeposit[std::size_t(cell)] == 0.0) depositCells.push_back(cell);
    cellDeposit[std::size_t(cell)] += droplets;
    balance.deposited += droplets;
  }

  double airborne() const {
    double sum = 0.0;
    for (double n : parcels.droplets) sum += n;
    return sum;
  }
};

}  // namespace rcfd
