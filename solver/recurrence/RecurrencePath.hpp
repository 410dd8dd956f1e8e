#pragma once
/// \file RecurrencePath.hpp
/// A recurrence path: the frame index to use at every rCFD step. Consecutive frames form sequences;
/// a step whose frame is not the previous frame + 1 is a jump (tracer steps never interpolate across
/// one). Generators are registered by name ("paper", "markov", "file") and seeded: the same seed
/// gives the same path.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/Registry.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

struct RecurrencePath {
  std::vector<int> frames;  ///< frame index per step

  bool isJump(std::int64_t step) const {
    return step > 0 && frames[std::size_t(step)] != frames[std::size_t(step - 1)] + 1;
  }
  std::int64_t jumpCount() const;
};

struct PathStatistics {
  std::int64_t jumps = 0;
  /// Mean R(from, to - 1) over the jumps from frame `from` to frame `to`: the similarity of the state
  /// left to the state the jump matched (a jump continues at the frame after the matched state).
  double meanJumpSimilarity = 0.0;
  double meanSequenceLength = 0.0;  ///< [frames]
};

/// Builds paths from a recurrence matrix R (N x N, symmetric, unit diagonal).
class PathGenerator {
 public:
  virtual ~PathGenerator() = default;
  virtual RecurrencePath generate(const Eigen::MatrixXf& recurrence, std::int64_t steps,
                                  std::uint64_t seed) const = 0;
};

using PathGeneratorRegistry = Registry<PathGenerator, const PathSpec&>;

PathStatistics pathStatistics(const RecurrencePath& path, const Eigen::MatrixXf& recurrence);

}  // namespace rcfd
