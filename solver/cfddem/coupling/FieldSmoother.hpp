#pragma once
/// \file FieldSmoother.hpp
/// Smoothing of coupling fields by the conservative diffusion equation Eq. (3),
///   d gamma / d t = (L_smooth^2 / dt_CFD) lap gamma,
/// integrated over one dt_CFD, i.e. a diffusion of total "D t" = L_smooth^2 (Pirker et al. 2011, Radl et
/// al. 2014). Explicit flux form between open face neighbours, in sub-steps short enough that every new
/// value is a convex combination of old ones (no new extrema, no negative alpha_P). Each flux is added
/// to one cell and taken from the other, so the integral over the open volume, sum V phi_c gamma_c, is
/// unchanged to round-off. The operator is self-adjoint in that volume-weighted inner product, which
/// keeps the momentum exchange exact when the gas velocity the parcels see is smoothed the same way.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "cfddem/coupling/VolumeMapping.hpp"

namespace rcfd::coupling {

class FieldSmoother {
 public:
  /// Faces between two usable cells with open aperture (faceOpen(d, lo, hi) > 0) conduct with
  /// conductance min(phi_lo, phi_hi) * A_d / h_d (cut cells cannot destabilise the explicit steps).
  /// length: L_smooth [m]; 0 makes smooth() the identity.
  FieldSmoother(const VolumeMapping& mapping, const std::vector<char>& faceOpen0,
                const std::vector<char>& faceOpen1, const std::vector<char>& faceOpen2, double length);

  double length() const { return length_; }
  int subSteps() const { return subSteps_; }

  /// Smooths a per-volume field (gamma per cell; its integral sum V phi gamma is conserved).
  void smooth(std::vector<double>& gamma) const;
  void smooth(std::vector<Eigen::Vector3d>& gamma) const;
  void smooth(std::vector<Eigen::Vector4d>& gamma) const;

 private:
  template <class T>
  void smoothImpl(std::vector<T>& gamma) const;

  const VolumeMapping& mapping_;
  double length_;
  int subSteps_ = 0;
  std::size_t cells_ = 0;
  /// Zero cells before and after the grid in the padded layout: every +-stride neighbour of a cell is
  /// inside the array, so the sweep needs no bounds tests.
  std::size_t pad_ = 0;
  /// Per axis d, in the padded layout, per cell c: D dtau * conductance [m3] of the face between
  /// c - stride_d and c (0 when closed, at the grid's boundary or in the padding).
  std::array<std::vector<double>, 3> g_;
  std::array<std::size_t, 3> stride_{};
  std::vector<double> invVolume_;  ///< 1 / (V phi), 0 for unusable cells and the padding
};

}  // namespace rcfd::coupling
