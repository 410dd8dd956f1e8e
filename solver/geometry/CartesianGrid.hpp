#pragma once
/// \file CartesianGrid.hpp
/// A uniform Cartesian grid: origin (the low corner), spacing and shape (nx, ny, nz). Cells are stored
/// in C order with x fastest: flat index = (k * ny + j) * nx + i -- the layout of the field database.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>

namespace rcfd {

struct CartesianGrid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();   ///< low corner [m]
  Eigen::Vector3d spacing = Eigen::Vector3d::Ones();  ///< cell edge lengths [m]
  std::array<int, 3> shape{1, 1, 1};                  ///< nx, ny, nz

  std::int64_t cellCount() const { return std::int64_t(shape[0]) * shape[1] * shape[2]; }
  double cellVolume() const { return spacing.x() * spacing.y() * spacing.z(); }

  std::int64_t flatIndex(int i, int j, int k) const {
    return (std::int64_t(k) * shape[1] + j) * shape[0] + i;
  }
  std::array<int, 3> cellIjk(std::int64_t flat) const {
    const int i = int(flat % shape[0]);
    const int j = int((flat / shape[0]) % shape[1]);
    const int k = int(flat / (std::int64_t(shape[0]) * shape[1]));
    return {i, j, k};
  }
  Eigen::Vector3d cellCenter(int i, int j, int k) const {
    return origin + spacing.cwiseProduct(Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5));
  }
  Eigen::Vector3d upperCorner() const {
    return origin + spacing.cwiseProduct(Eigen::Vector3d(shape[0], shape[1], shape[2]));
  }
  /// Cell containing p, clamped to the grid (points on the upper faces belong to the last cell).
  std::array<int, 3> cellOf(const Eigen::Vector3d& p) const {
    std::array<int, 3> c{};
    for (int d = 0; d < 3; ++d) {
      const int n = int(std::floor((p[d] - origin[d]) / spacing[d]));
      c[d] = n < 0 ? 0 : (n >= shape[d] ? shape[d] - 1 : n);
    }
    return c;
  }
  std::int64_t flatIndexOf(const Eigen::Vector3d& p) const {
    const auto c = cellOf(p);
    return flatIndex(c[0], c[1], c[2]);
  }
  bool operator==(const CartesianGrid& o) const {
    return origin == o.origin && spacing == o.spacing && shape == o.shape;
  }
};

}  // namespace rcfd
