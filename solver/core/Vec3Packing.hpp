#pragma once
/// \file Vec3Packing.hpp
/// Arrays of 3-vectors to and from flat [n][3] doubles: the layout checkpoints store them in.

#include <Eigen/Core>
#include <vector>

namespace rcfd {

/// [n] vectors -> [3n] doubles, x y z per vector.
inline std::vector<double> flattenVec3(const std::vector<Eigen::Vector3d>& v) {
  std::vector<double> out(3 * v.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int a = 0; a < 3; ++a) out[3 * i + std::size_t(a)] = v[i][a];
  return out;
}

/// [3n] doubles -> [n] vectors (a trailing remainder of fewer than 3 values is ignored).
inline std::vector<Eigen::Vector3d> unflattenVec3(const std::vector<double>& v) {
  std::vector<Eigen::Vector3d> out(v.size() / 3);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = Eigen::Vector3d(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
  return out;
}

}  // namespace rcfd
