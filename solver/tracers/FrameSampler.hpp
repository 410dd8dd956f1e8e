#pragma once
/// \file FrameSampler.hpp
/// Reads recurrence fields at arbitrary points: cell values and trilinear interpolation between cell
/// centres (constant extrapolation beyond the outermost centres), optionally blended linearly between
/// two consecutive frames of a sequence when the tracer time step is smaller than dt_rec. The tracer
/// motion kernel uses its own per-step copy of the velocity (tracers/StepField.hpp); this class serves
/// the effects that sample a few points (probes, spray parcels, averages).

#include <algorithm>
#include <cmath>

#include "fields/FieldDatabase.hpp"
#include "geometry/CartesianGrid.hpp"
#include "tracers/Trilinear.hpp"

namespace rcfd {

class FrameSampler {
 public:
  /// plates: per cell the plate faces interpolation does not cross (TrilinearLocator), or null.
  FrameSampler(const CartesianGrid& grid, const FieldFrame* frame, const FieldFrame* next = nullptr,
               double blend = 0.0, const std::uint8_t* plates = nullptr)
      : locator_(grid, plates), a_(frame), b_(next && blend > 0.0 ? next : nullptr), w_(blend) {}

  const FieldFrame& frame() const { return *a_; }
  const FieldFrame* nextFrame() const { return b_; }
  double blend() const { return b_ ? w_ : 0.0; }
  const TrilinearLocator& locator() const { return locator_; }

  /// alpha_P^rec of a cell.
  double alphaP(std::int64_t cell) const {
    const double va = a_->alpha_p[std::size_t(cell)];
    return b_ ? va + w_ * (b_->alpha_p[std::size_t(cell)] - va) : va;
  }

  /// u_P^rec (useGas = false) or u_G^rec (useGas = true) at p, trilinear between cell centres.
  Eigen::Vector3d velocity(const Eigen::Vector3d& p, bool useGas) const {
    const TrilinearStencil s = locator_.locate(p);
    const float* fa = (useGas ? a_->u_g : a_->u_p).data();
    const float* fb = b_ ? (useGas ? b_->u_g : b_->u_p).data() : nullptr;
    Eigen::Vector3d corners[8];
    for (int c = 0; c < 8; ++c) {
      const std::size_t at = std::size_t(3 * (s.base + locator_.offset(c)));
      corners[c] = Eigen::Vector3d(fa[at], fa[at + 1], fa[at + 2]);
      if (fb) corners[c] += w_ * (Eigen::Vector3d(fb[at], fb[at + 1], fb[at + 2]) - corners[c]);
    }
    return trilinear(corners, s.f);
  }

 private:
  TrilinearLocator locator_;
  const FieldFrame* a_;
  const FieldFrame* b_;
  double w_;
};

}  // namespace rcfd
