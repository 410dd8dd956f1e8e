#pragma once
/// \file MotionStatistics.hpp
/// What the tracer motion of one step did, counted for diagnostics and tests.

#include <cstdint>

namespace rcfd {

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

}  // namespace rcfd
