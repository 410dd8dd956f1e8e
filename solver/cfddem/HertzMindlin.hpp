#pragma once
/// \file HertzMindlin.hpp
/// Hertz-Mindlin contact with tangential history and Coulomb limit, damping from the coefficient of
/// restitution, as LIGGGHTS' `model hertz tangential history` (docs/dem.md):
///   k_n = 4/3 Y* sqrt(R* delta),  S_n = 2 Y* sqrt(R* delta),  k_t = S_t = 8 G* sqrt(R* delta),
///   gamma_n = -2 sqrt(5/6) beta sqrt(S_n m*),  gamma_t = -2 sqrt(5/6) beta sqrt(S_t m*),
///   F_n = k_n delta - gamma_n v_n,  F_t = -k_t xi - gamma_t v_t, |F_t| <= mu |F_n| (xi rescaled).
/// With this damping the restitution of a Hertzian impact is e for any impact velocity and size.

#include <cmath>

#include "cfddem/ContactModel.hpp"
#include "cfddem/RollingFrictionCdt.hpp"

namespace rcfd {

/// The force law of one contact. n points from the second body to the first; delta > 0 is the
/// overlap; vc is the relative velocity of the contact points (first minus second).
struct HertzMindlinContact {
  Eigen::Vector3d force;     ///< on the first body [N]
  Eigen::Vector3d n_x_ft;    ///< n x F_t, from which the torques follow with each body's arm
  Eigen::Vector3d roll;      ///< rolling torque on the first body [N m] (zero without rolling)
};

template <bool Rolling>
inline void hertzMindlinContact(const ContactParams& p, double delta, const Eigen::Vector3d& n,
                                const Eigen::Vector3d& vc, const Eigen::Vector3d& w_rel,
                                double m_eff, double r_eff, double dt, Eigen::Vector3d& shear,
                                HertzMindlinContact& out) {
  constexpr double two_sqrt_five_sixths = 1.8257418583505537;  // 2 sqrt(5/6)
  const double sqrtval = std::sqrt(r_eff * delta);
  const double kn = 4.0 / 3.0 * p.y_eff * sqrtval;
  const double sn = 2.0 * p.y_eff * sqrtval;
  const double kt = 8.0 * p.g_eff * sqrtval;
  const double gn = -two_sqrt_five_sixths * p.beta * std::sqrt(sn * m_eff);
  const double gt = -two_sqrt_five_sixths * p.beta * std::sqrt(kt * m_eff);

  const double vn = vc.dot(n);
  const double f_elastic = kn * delta;
  const double fn = f_elastic - gn * vn;
  const Eigen::Vector3d vt = vc - vn * n;

  // Tangential spring: integrate the sliding displacement, keep it in the current tangent plane.
  shear += vt * dt;
  shear -= shear.dot(n) * n;
  Eigen::Vector3d ft = -kt * shear;
  const double ft_spring = kt * shear.norm();
  const double ft_max = p.friction * std::abs(fn);
  if (ft_spring > ft_max) {
    // Sliding: Coulomb limit; the spring is reset to the limit so that stick resumes smoothly.
    if (ft_spring > 0.0) {
      ft *= ft_max / ft_spring;
      shear = -ft / kt;
    } else {
      ft.setZero();
    }
  } else {
    ft -= gt * vt;
  }
  out.force = fn * n + ft;
  out.n_x_ft = n.cross(ft);
  if constexpr (Rolling) {
    out.roll = RollingFrictionCdt::torque(p.rolling, f_elastic, r_eff, w_rel, n);
  } else {
    out.roll.setZero();
  }
}

class HertzMindlin final : public ContactModel {
 public:
  explicit HertzMindlin(const DemMaterial& material) : material_(material) {}
  std::string name() const override { return "hertz_mindlin"; }
  void setRollingModel(const RollingModel* rolling) override;
  void computePairs(ContactContext& ctx) const override;
  void computeWalls(ContactContext& ctx, long i, Eigen::Vector3d& force, Eigen::Vector3d& torque,
                    double& max_overlap, long& contacts) const override;

 private:
  template <bool Rolling, bool Direct> void pairs(ContactContext& ctx) const;
  template <bool Rolling>
  void walls(ContactContext& ctx, long i, Eigen::Vector3d& force, Eigen::Vector3d& torque,
             double& max_overlap, long& contacts) const;
  DemMaterial material_;
  bool rolling_ = false;
};

}  // namespace rcfd
