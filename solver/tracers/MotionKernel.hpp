#pragma once
/// \file MotionKernel.hpp
/// Moves every tracer through one rCFD step: Eq. (9) transport with the Eq. (10) fluctuation, free
/// flight under single-sphere drag and gravity where alpha_P^rec is below free_flight_alpha, the
/// stream velocity of velocity_streams (TracerContext::streamVelocity) where given, and
/// reflection at the apparatus's exact walls. Tracers faster than one cell per step are sub-stepped
/// (particle Courant number <= max_courant). Each tracer is independent and draws from its own
/// counter-based random stream, so results are bit-identical for any thread count.

#include <cstdint>
#include <functional>
#include <vector>

#include "geometry/Apparatus.hpp"
#include "tracers/StepField.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace block {
struct BlockStencils;
struct Context;
struct DeferredLanes;
struct Lanes;
}  // namespace block

/// Counters of the last step (for diagnostics and tests).
struct MotionStatistics {
  std::int64_t substeps = 0;        ///< sub-steps taken beyond the first
  std::int64_t wallHits = 0;        ///< reflections
  std::int64_t freeFlight = 0;      ///< tracers in free flight
  std::int64_t substepCapped = 0;   ///< tracers that needed more than kMaxSubsteps
  std::int64_t scalarPath = 0;      ///< tracers moved one by one (free flight, or the block path off)
  std::int64_t exactWallTests = 0;  ///< block-path sub-steps that needed the exact segment test
  std::int64_t blocksInPlace = 0;   ///< blocks whose later sub-steps ran in place (advanceInPlace())
};

class MotionKernel {
 public:
  static constexpr int kMaxSubsteps = 64;   ///< beyond this, walls still hold (exact segment tests)
  static constexpr int kMaxBounces = 16;    ///< reflections within one sub-step before stopping

  MotionKernel(const TracerContext& ctx, const MotionSettings& settings);

  /// Moves the tracers one step. `beside`, if given, runs once on one thread of the kernel's team
  /// while the other threads move tracers (that thread then joins them); it must not touch what the
  /// move reads or writes. With one thread it runs before the move.
  void move(TracerContext& ctx, const std::function<void()>& beside = {});
  const MotionStatistics& statistics() const { return stats_; }
  const MotionSettings& settings() const { return settings_; }

  /// Moves p by disp, reflecting at walls (mirror of the remaining displacement); v is reflected with
  /// the restitution coefficient if `velocity` is non-null. Returns the number of reflections.
  /// `clearance`, if >= 0, is the wall clearance of p's cell (saves looking it up).
  int moveWithWalls(Eigen::Vector3d& p, Eigen::Vector3d disp, Eigen::Vector3d* velocity,
                    double restitution, double clearance = -1.0) const;

 private:
  /// Builds the step's velocity fields and cell table from the context's frames and tracer alpha_P.
  void prepare(TracerContext& ctx, const FrameSampler& sampler, bool fluctuate);
  // The block path (MotionKernelBlock.cpp).
  /// The sub-steps after the first of lanes: rounds on the lanes that still have some, compacted.
  void advanceLanes(block::Lanes& lanes, std::int32_t maxLeft, block::BlockStencils& stencils, bool freeFlying,
                    const block::Context& bc, MotionStatistics& st) const;
  /// The sub-steps after the first of the lanes of a block in place, when most of its lanes have some
  /// (in the spout every lane does): rounds over the whole block, in which the lanes without sub-steps
  /// left stand still (a zero sub-step) and keep their velocity. Spares the copies of defer().
  void advanceInPlace(block::Lanes& lanes, block::BlockStencils& stencils, const block::Context& bc,
                      MotionStatistics& st) const;
  /// Adds the lanes with sub-steps left (lane k is tracer i0 + k, or i0 + laneOf[k]) to `deferred`,
  /// finishing its lanes whenever it is full.
  void defer(const block::Lanes& lanes, std::int64_t i0, const std::int32_t* laneOf, block::DeferredLanes& deferred,
             bool freeFlying, block::BlockStencils& stencils, const block::Context& bc, MotionStatistics& st) const;
  /// The remaining sub-steps of deferred lanes, then their positions (and velocities) into the cloud.
  void finishDeferred(block::DeferredLanes& deferred, bool freeFlying, block::BlockStencils& stencils,
                      const block::Context& bc, MotionStatistics& st) const;
  /// One sub-step of lanes along u_P^rec + u_fluc (sampled at the start already when `sampled`).
  void subStep(block::Lanes& lanes, block::BlockStencils& stencils, bool sampled, const block::Context& bc,
               MotionStatistics& st) const;
  /// One sub-step of free-flying lanes: drag toward u_G^rec and gravity, then the move.
  void freeFlightSubStep(block::Lanes& lanes, block::BlockStencils& stencils, const block::Context& bc,
                         MotionStatistics& st) const;
  /// The moves of a sub-step: the vectorised wall tests, then the exact segment test (and, for free
  /// flight, the velocity's reflection) for the moves they do not clear.
  void moveLanes(block::Lanes& lanes, const block::Context& bc, MotionStatistics& st, bool freeFlying) const;

  MotionSettings settings_;
  const Apparatus& apparatus_;
  const CartesianGrid& grid_;
  std::vector<float> clearance_;  ///< lower bound of the wall distance from any point of each cell [m]
  std::vector<float> reach_;      ///< wall distance of each cell centre less the hit band [m]
  std::vector<float> plateReach_; ///< draft-plate distance of each cell centre less the band [m] (plates only)
  std::vector<Apparatus::HalfSpace> halfSpaces_;  ///< the open region's convex part
  /// Per cell, the half-spaces a move of at most nearReach_ may come near (nearHalfSpaceMasks())
  std::vector<std::uint32_t> nearHalfSpaces_;
  double nearReach_ = 0.0;        ///< [m]
  double minSpacing_;
  double inverseStokesTime_;      ///< 18 rho_G nu_G / (rho_P d_P^2) [1/s]
  double reynoldsPerSpeed_;       ///< d_P / nu_G [s/m]
  Eigen::Vector3d gravity_{0.0, -9.81, 0.0};
  MotionStatistics stats_;
  const StepVelocityField* particleVelocity_ = nullptr;  ///< u_P^rec of the step (TracerContext::stepFields)
  const StepVelocityField* gasVelocity_ = nullptr;       ///< u_G^rec of the step (free flight only)
  /// Per cell, the two numbers a tracer reads from its own cell, side by side so they cost one cache
  /// line: [2c] reach_ [m] (0 without walls), [2c+1] |u_fluc| of Eq. (10) capped at
  /// u_fluc_max [m/s] (0 without fluctuation).
  std::vector<float> cellData_;
  bool hadSpeeds_ = false;  ///< cellData_ holds speeds of an earlier step (zeroed when fluctuation stops)
};

}  // namespace rcfd
