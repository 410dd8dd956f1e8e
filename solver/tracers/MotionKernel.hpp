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
/// test Kernel.BlockPathMatchesTheReferenceMotionOnRandomCases holds the two together. The block path
/// (BlockPath.cpp) is compiled once per instruction set (core/Isa.hpp) and runs the variant
/// kernelIsa() picks. Its strategies:
///  - **Per-cell work once per step** (prepare()): Eq. (10)'s speed depends on the cell only, so it is
///    computed per cell, beside each cell's wall reach, and a lane reads both with one load.
///  - **Blocks in place** (startBlock(), moveBlock()): a block's lanes are the cloud's own arrays; only
///    a block with tracers in free flight copies its two kinds of lanes apart (takeLanes()).
///  - **Two wall tests before the exact one** (moveLanes()): a move shorter
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

#include "core/Isa.hpp"
#include "geometry/Apparatus.hpp"
#include "tracers/MotionStatistics.hpp"
#include "tracers/ReferenceMotion.hpp"
#include "tracers/StepField.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace block {
struct Context;
struct StepInputs;
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
  /// The instruction set of the block path's variant: kernelIsa() unless selectIsa() chose another.
  Isa isa() const { return isa_; }
  /// Runs the block path's variant for `isa` (one of builtIsas() this CPU runs): tests and benchmarks
  /// compare the variants on one machine.
  void selectIsa(Isa isa);

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
  Isa isa_ = Isa::avx2;
  void (*moveTracers_)(const block::StepInputs&, const std::function<void()>&, MotionStatistics&) = nullptr;
  const StepVelocityField* particleVelocity_ = nullptr;  ///< u_P^rec of the step (TracerContext::stepFields)
  const StepVelocityField* gasVelocity_ = nullptr;       ///< u_G^rec of the step (free flight only)
  /// Per cell, the two numbers a tracer reads from its own cell, side by side so they cost one cache
  /// line: [2c] reach_ [m] (0 without walls), [2c+1] |u_fluc| of Eq. (10) capped at
  /// u_fluc_max [m/s] (0 without fluctuation).
  std::vector<float> cellData_;
  bool hadSpeeds_ = false;  ///< cellData_ holds speeds of an earlier step (zeroed when fluctuation stops)
};

}  // namespace rcfd
