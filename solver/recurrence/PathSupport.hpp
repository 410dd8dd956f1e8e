#pragma once
/// \file PathSupport.hpp
/// Checks shared by the path generators: the recurrence matrix and the sequence settings of PathSpec.

#include <Eigen/Core>
#include <cmath>
#include <string>

#include "core/Errors.hpp"
#include "fields/FieldDatabase.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

/// N x N with N >= 3 (the database minimum), every entry finite.
inline void checkPathRecurrence(const Eigen::MatrixXf& R) {
  if (R.rows() != R.cols() || R.rows() < layout::minimumFrames) {
    throw InputError("recurrence path", "/recurrence/matrix",
                     "is " + std::to_string(R.rows()) + " x " + std::to_string(R.cols()) +
                         "; a path needs a square matrix over at least 3 frames");
  }
  if (!R.allFinite()) throw InputError("recurrence path", "/recurrence/matrix", "holds NaN or infinity");
}

/// 0 < min_sequence_fraction <= max_sequence_fraction <= 1.
inline void checkSequenceFractions(const PathSpec& spec) {
  if (!(spec.min_sequence_fraction > 0.0 && spec.min_sequence_fraction <= 1.0)) {
    throw InputError("scene", "/rcfd/path/min_sequence_fraction",
                     std::to_string(spec.min_sequence_fraction) + " is outside (0, 1]");
  }
  if (!(spec.max_sequence_fraction >= spec.min_sequence_fraction && spec.max_sequence_fraction <= 1.0)) {
    throw InputError("scene", "/rcfd/path/max_sequence_fraction",
                     std::to_string(spec.max_sequence_fraction) +
                         " must lie in [min_sequence_fraction, 1] = [" +
                         std::to_string(spec.min_sequence_fraction) + ", 1]");
  }
}

inline void checkSteps(std::int64_t steps) {
  if (steps < 0) throw InputError("recurrence path", "steps", std::to_string(steps) + " is negative");
}

}  // namespace rcfd
