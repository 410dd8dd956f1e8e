#pragma once
/// \file BlockLanes.hpp
/// The motion kernel's block path (internal): the lanes of a block of tracers that move together
/// through one sub-step pass, and the step's constants those passes read as plain values (the
/// vectoriser does not look through members of the kernel).

#include <bit>
#include <cmath>
#include <cstdint>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "core/IsaNamespace.hpp"
#include "tracers/BlockSampling.hpp"
#include "tracers/CellIndex.hpp"
#include "tracers/CounterRng.hpp"
#include "tracers/FrameSampler.hpp"

namespace rcfd {
class ReferenceMotion;
}

namespace rcfd::block {

/// Tracer lanes of a block that move along u_P^rec (not in free flight), in one sub-step pass: views
/// of the cloud's arrays (the common case, no copies) or of a LaneStorage (compacted lanes).
struct Lanes {
  double *x, *y, *z;         ///< position [m]
  const float *ax, *ay, *az;  ///< u_fluc of Eq. (10) [m/s]
  double *ux, *uy, *uz;      ///< velocity of the sub-step [m/s]
  double* h;                 ///< sub-step [s]
  std::int32_t* left;        ///< sub-steps still to take after this pass
  int count = 0;
  /// The cells of the positions (the step's first pass: the tracers' cells), or null (later passes)
  const std::int32_t* cell = nullptr;
  /// With `cell`: each lane's MotionKernel::cellData_ reach, loaded with its Eq. (10) speed
  const float* reach = nullptr;
};

/// Storage of compacted lanes.
struct LaneStorage {
  alignas(64) double x[kBlock], y[kBlock], z[kBlock];
  alignas(64) float ax[kBlock], ay[kBlock], az[kBlock];
  alignas(64) double ux[kBlock], uy[kBlock], uz[kBlock];
  alignas(64) double h[kBlock];
  alignas(64) std::int32_t left[kBlock];
  alignas(64) std::int32_t cell[kBlock];
  alignas(64) float reach[kBlock];
  std::int32_t lane[kBlock];  ///< the lane's index in the lanes it was compacted from
  Lanes view(int count, bool withCells = false) {
    return {x, y, z, ax, ay, az, ux, uy, uz, h, left, count, withCells ? cell : nullptr, withCells ? reach : nullptr};
  }
  /// Copies lane k of `from` (position, u_fluc, sub-step, sub-steps left, and the velocity if
  /// `velocity`) into lane j. A pass along u_P^rec samples its velocity before reading it, so only
  /// free flight needs the velocity copied in.
  void copyLane(const Lanes& from, int k, int j, bool velocity) {
    x[j] = from.x[k], y[j] = from.y[k], z[j] = from.z[k];
    ax[j] = from.ax[k], ay[j] = from.ay[k], az[j] = from.az[k];
    if (velocity) ux[j] = from.ux[k], uy[j] = from.uy[k], uz[j] = from.uz[k];
    h[j] = from.h[k];
    left[j] = from.left[k];
  }
};

// Code that differs by instruction set, and its callers: one definition per kernel variant
// (core/IsaNamespace.hpp).
inline namespace RCFD_ISA_NAMESPACE {

/// The lanes k < n with v[k] > 0, in lane order, into `out`; returns their number. A bit mask of them
/// first (eight lanes per compare with AVX2), then its set bits: where few lanes qualify, a lane-by-lane
/// pass over all 64 costs more than the mask, and a branch per lane mispredicts.
inline int positiveLanes(const std::int32_t* v, int n, std::int32_t* out) {
  static_assert(kBlock <= 64, "one bit per lane in a 64-bit mask");
  std::uint64_t mask = 0;
  int k = 0;
#if defined(__AVX2__)
  for (; k + 8 <= n; k += 8) {
    const __m256i more = _mm256_cmpgt_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(v + k)),
                                            _mm256_setzero_si256());
    mask |= std::uint64_t(std::uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(more)))) << k;
  }
#endif
  for (; k < n; ++k) mask |= std::uint64_t(v[k] > 0) << k;
  int r = 0;
  for (; mask != 0; mask &= mask - 1) out[r++] = std::countr_zero(mask);
  return r;
}

/// The lanes of `lanes` with sub-steps left, in lane order, into `out`; returns their number.
inline int lanesWithSubstepsLeft(const Lanes& lanes, std::int32_t* out) {
  return positiveLanes(lanes.left, lanes.count, out);
}

/// The number of lanes with sub-steps left.
inline int countLanesWithSubstepsLeft(const Lanes& lanes) {
  const std::int32_t* const left = lanes.left;
  std::int32_t r = 0;
#pragma omp simd reduction(+ : r)
  for (int k = 0; k < lanes.count; ++k) r += left[k] > 0 ? 1 : 0;
  return r;
}

}  // namespace RCFD_ISA_NAMESPACE

/// A block whose lanes with sub-steps left after their first are at least this many takes those
/// sub-steps in place (advanceInPlace(), BlockPath.cpp), every lane in every pass; fewer are deferred.
/// Break-even: a deferred lane costs its copies plus its share of a full pass, a pass in place
/// about as much as 64 lanes' passes; in the benchmark's spout every lane has one.
constexpr int kInPlaceLanes = 32;

/// Lanes, from the blocks a thread moves, with sub-steps left after their first: moved together when
/// the storage is full or the thread has no chunk left, so later sub-steps run on full vectors rather
/// than on the one or two lanes a block has (each pass has a fixed cost, which per-block passes of
/// a few lanes would pay many times). Which lanes share a pass depends on the schedule; a lane's
/// arithmetic does not.
struct DeferredLanes {
  LaneStorage s;
  std::int64_t tracer[kBlock];  ///< the lane's tracer
  int count = 0;
};

/// What every sub-step pass of moveTracers() reads: the step field, the grid and the walls as plain values.
struct Context {
  const float* field = nullptr;     ///< u_P^rec of the step, 4 floats per cell
  const float* gasField = nullptr;  ///< u_G^rec of the step, 4 floats per cell (free flight only)
  const float* cellData = nullptr;  ///< MotionKernel::cellData_
  const float* plateReach = nullptr;  ///< per cell, or null without draft plates
  TrilinearLocator::Constants q{};
  GridConstants grid;               ///< q for grid coordinates in float
  CornerOffsets corners;            ///< corner offsets in floats of the step fields
  double origin[3] = {}, inv[3] = {}, spacing[3] = {};
  int last[3] = {};
  std::int32_t sy = 0, sz = 0;
  static constexpr int kMaxHalfSpaces = 16;
  int halfSpaces = 0;               ///< 0: no half-space test (walls off, or an outline too complex)
  double hx[kMaxHalfSpaces] = {}, hy[kMaxHalfSpaces] = {}, hz[kMaxHalfSpaces] = {}, hc[kMaxHalfSpaces] = {};
  double margin = 0.0;              ///< 2 boundaryTolerance() [m]
  /// Per cell, the half-spaces a move of at most sqrt(nearReach2) from it may come within `margin` of
  /// (nearHalfSpaceMasks()); null: test them all
  const std::uint32_t* nearHalfSpaces = nullptr;
  double nearReach2 = 0.0;          ///< [m2]
  double noWall = 0.0;              ///< 1e300 without walls: every move is within reach
  double halfDiagonal = 0.0;        ///< half a cell diagonal: no point of a cell is farther from its centre [m]
  static constexpr int kMaxSubsteps = 64;  ///< MotionKernel::kMaxSubsteps
  double substepLength[kMaxSubsteps + 1] = {};  ///< [n] = dt / n [s]
  double inverseStokesTime = 0.0;   ///< 18 rho_G nu_G / (rho_P d_P^2) [1/s]
  double reynoldsPerSpeed = 0.0;    ///< d_P / nu_G [s/m]
  double gravity[3] = {};           ///< [m/s2]
  double restitution = 1.0;         ///< normal restitution of free-flying tracers at walls [-]
  bool midpoint = true;
  /// The cloud, where deferred lanes are written back; velocities only when keepVelocity (free flight).
  double *cloudX = nullptr, *cloudY = nullptr, *cloudZ = nullptr;
  double *cloudVx = nullptr, *cloudVy = nullptr, *cloudVz = nullptr;
  bool keepVelocity = false;
  /// The exact wall test for the moves the vectorised tests do not clear (ReferenceMotion::moveReflecting())
  const ReferenceMotion* exact = nullptr;
  /// The tracers' cells after the move (TracerContext::nextTracerCell), or null; with `cellIndexer`.
  std::int32_t* nextCells = nullptr;
  const CellIndexer* cellIndexer = nullptr;
};

/// The cloud's coordinate and velocity arrays.
struct Cloud {
  double *x, *y, *z, *vx, *vy, *vz;
};

/// What every block of a step reads besides the Context: the cloud and the step's per-tracer inputs.
struct StepInputs {
  Cloud cloud{};
  std::int64_t tracers = 0;                   ///< the cloud's size
  const Context* context = nullptr;
  const std::int32_t* ids = nullptr;          ///< the tracers' ids (their random streams)
  const FrameSampler* sampler = nullptr;      ///< alpha_P^rec (free flight)
  const CellIndexer* indexer = nullptr;
  const CounterRngPrefix* rngPrefix = nullptr;
  const std::int32_t* tracerCell = nullptr;   ///< the cells tracer_volume_fraction found, or null
  bool fluctuate = false;                     ///< Eq. (10) on
  const float *streamX = nullptr, *streamY = nullptr, *streamZ = nullptr;  ///< velocity_streams, or null
  double dt = 0.0;                            ///< [s]
  double inverseCellLimit = 0.0;              ///< 1 / (max_courant x smallest spacing) [1/m]
  bool freeFlight = false;                    ///< MotionSettings::freeFlight
  double freeFlightAlpha = 0.0;               ///< MotionSettings::freeFlightAlpha [-]
};

/// A block's lanes at the start of the step: their cells, which are in free flight, their cells' reach
/// (the first wall test) and u_fluc (Eq. (10), with the stream velocity).
struct BlockStart {
  alignas(64) float ax[kBlock], ay[kBlock], az[kBlock];  ///< u_fluc [m/s]
  alignas(64) float reach[kBlock];                       ///< MotionKernel::cellData_'s reach of the lane's cell [m]
  alignas(64) std::int32_t cellsFound[kBlock];
  const std::int32_t* cell = nullptr;  ///< the lanes' cells: StepInputs::tracerCell + i0, or cellsFound
  std::int64_t free[kBlock];           ///< free flight (not bool, which stops the vectoriser)
  std::int64_t freeLanes = 0;
};

/// A thread's lanes with sub-steps left, carried from block to block so that their passes run full,
/// and its stencils.
struct ThreadLanes {
  DeferredLanes deferred, deferredFree;
  BlockStencils stencils;
};

// Code that differs by instruction set, and its callers: one definition per kernel variant
// (core/IsaNamespace.hpp).
inline namespace RCFD_ISA_NAMESPACE {

/// Eq. (9): u = u_P^rec + u_fluc at the lanes' positions, located in float grid coordinates: into the
/// lanes' velocities, and in float with the grid coordinates into `s` (the midpoint rule steps from them).
inline void sampleParticleVelocity(const Context& bc, Lanes& L, BlockStencils& s) {
  gridCoordinatesOfBlock(bc.grid, L.count, L.x, L.y, L.z, s.gx, s.gy, s.gz);
  locateGridBlock(bc.grid, L.count, s.gx, s.gy, s.gz, s);
  sampleBlockFloat(bc.field, bc.corners, s, L.count, L.ax, L.ay, L.az, s.ux, s.uy, s.uz, L.ux, L.uy, L.uz);
}

/// Below this fraction of one limit squared, a lane's Courant number is at most 1 whatever the rounding
/// of the exact test in substepsOfBlock() (its relative error is a few 1e-16).
constexpr double kOneSubstepMargin = 1.0 - 1e-9;

/// Sub-steps of the lanes of a block so that none moves farther than max_courant cells at its start
/// velocity u: the arithmetic of ReferenceMotion::substepsFor() (courant = |u| dt / limit, given as
/// its inverse, capped at kMax, also for a non-finite u). The sub-step lengths come from `lengths`
/// (lengths[n] = dt / n, as there) on AVX-512, where the table gather beats a vector division;
/// elsewhere from the division itself (GCC does not gather on Zen, and a table loaded lane by lane is
/// slower). Adds the extra sub-steps and the capped lanes to the counters; returns the largest number
/// of extra sub-steps. Not inlined: inlined into its caller, GCC 12 leaves the loop scalar for AVX2
/// ("control flow in loop"); out of line it vectorises it.
[[gnu::noinline]] inline std::int32_t substepsOfBlock(const double* ux, const double* uy, const double* uz,
                                                      int count, double dt, double inverseLimit,
                                                      [[maybe_unused]] const double* lengths, double kMax,
                                                      double* h, std::int32_t* left, std::int64_t& extra,
                                                      std::int64_t& capped) {
  // Most blocks have no lane that moves farther than one limit (the tracers are sorted by cell, and
  // sub-steps cluster in the spout): a squared bound settles them without the square roots and the
  // table. Its margin keeps it inside the exact test below; NaN fails it and takes the exact path.
  const double scale = dt * inverseLimit;
  const double oneLimitSquared = kOneSubstepMargin / (scale * scale);
  alignas(64) std::int32_t beyondLane[kBlock];
  std::int32_t beyond = 0;
#pragma omp simd reduction(+ : beyond)
  for (int k = 0; k < count; ++k) {
    const double speed2 = ux[k] * ux[k] + uy[k] * uy[k] + uz[k] * uz[k];
    beyondLane[k] = std::int32_t(!(speed2 <= oneLimitSquared));
    beyond += beyondLane[k];
  }
#pragma omp simd
  for (int k = 0; k < count; ++k) h[k] = dt, left[k] = 0;  // dt / 1, as lengths[1]
  if (beyond == 0) return 0;
  // The exact count only for the lanes beyond one limit (10 of 64 on average where there are any),
  // gathered into full vectors: over all 64 lanes the square roots and the table cost twice the rest of
  // this function.
  alignas(64) double bx[kBlock], by[kBlock], bz[kBlock];
  alignas(64) double hb[kBlock];
  alignas(64) std::int32_t leftb[kBlock], over[kBlock];
  std::int32_t lane[kBlock];
  const int r = positiveLanes(beyondLane, count, lane);
  for (int j = 0; j < r; ++j) bx[j] = ux[lane[j]], by[j] = uy[lane[j]], bz[j] = uz[lane[j]];
#pragma omp simd
  for (int j = 0; j < r; ++j) {
    const double distance = std::sqrt(bx[j] * bx[j] + by[j] * by[j] + bz[j] * bz[j]) * dt;
    const double courant = distance * inverseLimit;
    const bool within = courant <= kMax;  // false also for NaN
    const double c = within ? courant : kMax;  // in [0, kMax]
    // ceil(c) in integers: GCC 12 vectorises neither ceil (without -fno-trapping-math) nor, for AVX2
    // (no masked operations), a select between rounded doubles; it left this loop scalar with two
    // branches that mispredict at every Courant boundary.
    const std::int32_t whole = std::int32_t(c);  // floor, as c >= 0
    const std::int32_t up = whole + std::int32_t(double(whole) < c);
    const std::int32_t nsub = up > 1 ? up : 1;
#if defined(__AVX512F__)
    hb[j] = lengths[nsub];
#else
    hb[j] = dt / double(nsub);  // = lengths[nsub]
#endif
    leftb[j] = nsub - 1;
    over[j] = within ? 0 : 1;
  }
  // Back to their lanes, and summed in int32 (at most kBlock * kMax).
  std::int32_t added = 0, cappedHere = 0;
  std::int32_t maxLeft = 0;
  for (int j = 0; j < r; ++j) {
    h[lane[j]] = hb[j], left[lane[j]] = leftb[j];
    added += leftb[j], cappedHere += over[j];
    maxLeft = leftb[j] > maxLeft ? leftb[j] : maxLeft;
  }
  extra += added, capped += cappedHere;
  return maxLeft;
}

}  // namespace RCFD_ISA_NAMESPACE

}  // namespace rcfd::block
