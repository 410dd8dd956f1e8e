#pragma once
/// \file MotionKernel.hpp
/// Moves every tracer through one rCFD step: Eq. (9) transport with the Eq. (10) fluctuation, free
/// flight under single-sphere drag and gravity where alpha_P^rec is below free_flight_alpha, the
/// stream velocity of velocity_streams (TracerContext::streamVelocity) where given, and
/// reflection at the apparatus's exact walls. Tracers faster than one cell per step are sub-stepped
/// (particle Courant number <= max_courant). Each tracer is independent and draws from its own
/// counter-based random stream, so results are bit-identical for any thread count.
///
/// What a tracer does is defined by ReferenceMotion (ReferenceMotion.hpp), one tracer at a time. This
/// kernel does the same to blocks of 64 tracers (block::kBlock) in loops the compiler vectorises; the
/// test Kernel.BlockPathMatchesTheReferenceMotionOnRandomCases holds the two together. Its strategies:
///  - **Per-cell work once per step** (prepare()): Eq. (10)'s speed depends on the cell only, so it is
///    computed per cell, beside each cell's wall reach, and a lane reads both with one load.
///  - **Blocks in place** (startBlock(), moveBlock()): a block's lanes are the cloud's own arrays; only
///    a block with tracers in free flight copies its two kinds of lanes apart (takeLanes()).
///  - **Two wall tests before the exact one** (moveLanes(), MotionKernelBlock.cpp): a move shorter
///    than its cell's wall reach, or clear of every half-space of the open region near its cell and of
///    the plates, cannot meet a wall; only the others take ReferenceMotion's exact segment test.
///  - **Sub-steps three ways**: most tracers take one sub-step (the block's first pass); a block in
///    which most lanes need more takes them in place, every lane in every pass (advanceInPlace(),
///    lanes done stand still); otherwise its few such lanes are deferred and gathered across blocks
///    until 64 move together (defer(), finishDeferred()), so later passes run on full vectors.
///  - **The next step's cells** are found for a chunk of blocks while its positions are in cache
///    (TracerContext::nextTracerCell), with the one CellIndexer every user of a tracer's cell shares.
/// Dynamic chunks of 16 blocks balance the threads: sub-stepped and near-wall tracers cluster.
/// Measured costs of each strategy: docs/performance.md, "Tracers (`rcfd-bench tracers`)".

#include <cstdint>
#include <functional>
#include <vector>

#include "geometry/Apparatus.hpp"
#include "tracers/MotionStatistics.hpp"
#include "tracers/ReferenceMotion.hpp"
#include "tracers/StepField.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace block {
struct BlockStart;
struct BlockStencils;
struct Context;
struct DeferredLanes;
struct Lanes;
struct StepInputs;
struct ThreadLanes;
}  // namespace block


class MotionKernel {
 public:
  static constexpr int kMaxSubsteps = ReferenceMotion::kMaxSubsteps;  ///< beyond this, walls still hold
  static constexpr int kMaxBounces = ReferenceMotion::kMaxBounces;    ///< reflections within one move

  MotionKernel(const TracerContext& ctx, const MotionSettings& settings);

  /// Moves the tracers one step. `beside`, if given, runs once on one thread of the kernel's team
  /// while the other threads move tracers (that thread then joins them); it must not touch what the
  /// move reads or writes. With one thread it runs before the move.
  void move(TracerContext& ctx, const std::function<void()>& beside = {});
  const MotionStatistics& statistics() const { return stats_; }
  const MotionSettings& settings() const { return settings_; }

  /// Moves p by disp, reflecting at walls (mirror of the remaining displacement); v is reflected with
  /// the restitution coefficient if `velocity` is non-null. Returns the number of reflections. The
  /// exact test of ReferenceMotion::moveReflecting(): the block path's moves its own tests do not clear.
  int moveWithWalls(Eigen::Vector3d& p, const Eigen::Vector3d& disp, Eigen::Vector3d* velocity,
                    double restitution) const;

 private:
  /// Builds the step's velocity fields and cell table from the context's frames and tracer alpha_P.
  void prepare(TracerContext& ctx, const FrameSampler& sampler, bool fluctuate);
  /// The step's constants of the block path: fields, grid and walls as plain values.
  block::Context blockContext(const TrilinearLocator& locator, double dt) const;
  /// A block's start: its lanes' cells, which are in free flight, their cells' reach and u_fluc.
  void startBlock(const block::StepInputs& in, std::int64_t i0, int count, block::BlockStart& b) const;
  /// A block's move: its first sub-step, the later ones in place or deferred, and its free flight.
  void moveBlock(const block::StepInputs& in, std::int64_t i0, int count, block::BlockStart& b,
                 block::ThreadLanes& thread, MotionStatistics& st) const;
  // The block path's sub-step rounds (MotionKernelBlock.cpp).
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
  ReferenceMotion reference_;  ///< every tracer when settings_.vectorised is false; the exact wall test
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
