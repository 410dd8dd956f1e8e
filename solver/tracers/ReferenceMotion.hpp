#pragma once
/// \file ReferenceMotion.hpp
/// The tracer motion of one rCFD step written plainly, one tracer at a time: the definition the motion
/// kernel's vectorised block path (MotionKernel.hpp) is tested against, and the path it takes for
/// every tracer when MotionSettings::vectorised is false.
///
/// Per tracer, in its cell c at the start of the step:
///  - free flight where alpha_P^rec(c) < free_flight_alpha: the tracer's own velocity relaxes toward
///    u_G^rec under single-sphere drag, implicitly (stable for any dt / tau), plus gravity;
///  - otherwise Eq. (9), dx/dt = u_P^rec(x) + u_fluc, by the midpoint rule (or Euler), with Eq. (10)'s
///    u_fluc = |u_fluc|(c) n: the fluctuation model's speed for the tracers' and the recurrence
///    fields' alpha_P of c, capped at u_fluc_max, along a unit vector n from the tracer's own
///    counter-based random stream, held over the step (and the stream velocity of velocity_streams);
///  - sub-steps so that none moves farther than max_courant cells;
///  - every move tested against the apparatus's exact walls (Apparatus::firstIntersection()) and
///    mirrored at them; free flight's velocity loses its normal part by the restitution.
/// u_P^rec is sampled in float at float grid coordinates, the precision of the fields themselves and
/// the block path's arithmetic, so both paths agree to the last bits of a fused multiply-add.
///
/// It keeps nothing between steps and precomputes nothing: no wall clearances, no per-cell speeds.

#include <Eigen/Core>

#include "geometry/Apparatus.hpp"
#include "tracers/MotionStatistics.hpp"
#include "tracers/TracerContext.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {

class ReferenceMotion {
 public:
  static constexpr int kMaxSubsteps = 64;  ///< beyond this, walls still hold (exact segment tests)
  static constexpr int kMaxBounces = 16;   ///< reflections within one move before stopping

  ReferenceMotion(const TracerContext& ctx, const MotionSettings& settings);

  /// Moves every tracer of ctx.cloud one step of ctx.dt; counts into `stats`. Writes
  /// ctx.nextTracerCell when it is sized to the cloud.
  void move(TracerContext& ctx, MotionStatistics& stats) const;

  /// Moves p by disp, mirroring the rest of the displacement at every wall it meets (at most
  /// kMaxBounces times); v, if given, loses (1 + restitution) times its normal part at each wall it
  /// moves into. Returns the number of reflections. Without walls p just moves.
  int moveReflecting(Eigen::Vector3d& p, Eigen::Vector3d disp, Eigen::Vector3d* velocity, double restitution) const;

  /// Sub-steps for a move of `distance` [m] in one step: ceil(distance / (max_courant x smallest
  /// spacing)), at least 1, at most kMaxSubsteps (then `capped` is counted).
  int substepsFor(double distance, std::int64_t& capped) const;

 private:
  MotionSettings settings_;
  const Apparatus& apparatus_;
  const CartesianGrid& grid_;
  double inverseCellLimit_;   ///< 1 / (max_courant x smallest spacing) [1/m]
  double inverseStokesTime_;  ///< 18 rho_G nu_G / (rho_P d_P^2) [1/s]
  double reynoldsPerSpeed_;   ///< d_P / nu_G [s/m]
  Eigen::Vector3d gravity_{0.0, -9.81, 0.0};
};

}  // namespace rcfd
