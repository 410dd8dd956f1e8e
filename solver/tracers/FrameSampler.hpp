#pragma once
/// \file FrameSampler.hpp
/// Reads recurrence fields at tracer positions: cell values and trilinear interpolation between cell
/// centres (constant extrapolation beyond the outermost centres), optionally blended linearly between
/// two consecutive frames of a sequence when the tracer time step is smaller than dt_rec.

#include <algorithm>
#include <cmath>

#include "fields/FieldDatabase.hpp"
#include "geometry/CartesianGrid.hpp"

namespace rcfd {

class FrameSampler {
 public:
  FrameSampler(const CartesianGrid& grid, const FieldFrame* frame, const FieldFrame* next = nullptr,
               double blend = 0.0)
      : grid_(grid), a_(frame), b_(next && blend > 0.0 ? next : nullptr), w_(blend) {
    for (int d = 0; d < 3; ++d) inv_[d] = 1.0 / grid.spacing[d];
  }

  const FieldFrame& frame() const { return *a_; }

  /// alpha_P^rec of a cell.
  double alphaP(std::int64_t cell) const {
    const double va = a_->alpha_p[std::size_t(cell)];
    return b_ ? va + w_ * (b_->alpha_p[std::size_t(cell)] - va) : va;
  }

  /// u_P^rec (useGas = false) or u_G^rec (useGas = true) at p, trilinear between cell centres.
  Eigen::Vector3d velocity(const Eigen::Vector3d& p, bool useGas) const {
    int i0[3], i1[3];
    double f[3];
    for (int d = 0; d < 3; ++d) {
      const int n = grid_.shape[d];
      double s = (p[d] - grid_.origin[d]) * inv_[d] - 0.5;
      s = std::clamp(s, 0.0, double(n - 1));
      int lo = std::min(int(s), std::max(n - 2, 0));
      i0[d] = lo;
      i1[d] = std::min(lo + 1, n - 1);
      f[d] = s - lo;
    }
    Eigen::Vector3d u = sampleCorners(useGas ? a_->u_g : a_->u_p, i0, i1, f);
    if (b_) u += w_ * (sampleCorners(useGas ? b_->u_g : b_->u_p, i0, i1, f) - u);
    return u;
  }

 private:
  Eigen::Vector3d sampleCorners(const std::vector<float>& field, const int* i0, const int* i1,
                                const double* f) const {
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    for (int c = 0; c < 8; ++c) {
      const int i = (c & 1) ? i1[0] : i0[0];
      const int j = (c & 2) ? i1[1] : i0[1];
      const int k = (c & 4) ? i1[2] : i0[2];
      const double w = ((c & 1) ? f[0] : 1.0 - f[0]) * ((c & 2) ? f[1] : 1.0 - f[1]) *
                       ((c & 4) ? f[2] : 1.0 - f[2]);
      const float* v = field.data() + 3 * grid_.flatIndex(i, j, k);
      u += w * Eigen::Vector3d(v[0], v[1], v[2]);
    }
    return u;
  }

  const CartesianGrid& grid_;
  const FieldFrame* a_;
  const FieldFrame* b_;
  double w_;
  double inv_[3];
};

}  // namespace rcfd
