#pragma once
/// \file RollingFrictionCdt.hpp
/// Rolling friction, constant directional torque (Ai et al. 2011, model A; LIGGGHTS `rolling_friction
/// cdt`): a torque of magnitude mu_r k_n delta R* opposing the relative angular velocity, without its
/// component about the contact normal (no torsion resistance).

#include <Eigen/Core>
#include <cmath>

#include "cfddem/ContactModel.hpp"

namespace rcfd {

class RollingFrictionCdt final : public RollingModel {
 public:
  std::string name() const override { return "cdt"; }

  /// Torque on the first body (the second gets the opposite): -mu_r F_el R* w/|w|, minus its normal
  /// part. w = omega_i - omega_j (omega_i for a wall); F_el = k_n delta, the elastic normal force.
  static Eigen::Vector3d torque(double mu_r, double f_elastic, double r_eff,
                                const Eigen::Vector3d& w_rel, const Eigen::Vector3d& n) {
    const double wmag = w_rel.norm();
    if (wmag <= 0.0) return Eigen::Vector3d::Zero();
    Eigen::Vector3d t = (mu_r * f_elastic * r_eff / wmag) * w_rel;
    t -= t.dot(n) * n;
    return -t;
  }
};

}  // namespace rcfd
