#pragma once
/// \file DemParticles.hpp
/// The DEM particles (or coarse-grained parcels) as a structure of arrays: one array per quantity, so
/// the force and integration loops stream through memory. Index i is a particle's identity for its
/// life until DemSystem sorts the particles spatially (for cache locality); `id` is the permanent
/// identity (the order of insertion).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace rcfd {

class DemParticles {
 public:
  using Vec3 = Eigen::Vector3d;

  /// Adds a sphere of radius r [m] and density rho [kg/m3] at position x with velocity v; returns its
  /// index. Mass 4/3 pi r^3 rho, moment of inertia 2/5 m r^2 (solid sphere).
  std::size_t add(const Vec3& x, const Vec3& v, double radius, double density);

  std::size_t size() const { return x.size(); }
  void reserve(std::size_t n);

  /// Reorders all arrays: new index k holds the particle that was at perm[k].
  void permute(const std::vector<std::size_t>& perm);

  /// Prevents particle i from rotating (infinite moment of inertia): a sliding block in tests.
  void lockRotation(std::size_t i) { inv_inertia[i] = 0.0; }

  /// Translational plus rotational kinetic energy [J] (summed in index order: deterministic).
  double kineticEnergy() const;
  /// Sum of m_i g.x_i [J] relative to the origin, for energy checks.
  double gravityPotential(const Vec3& gravity) const;

  std::vector<Vec3> x;        ///< position of the centre [m]
  std::vector<Vec3> v;        ///< translational velocity [m/s]
  std::vector<Vec3> omega;    ///< angular velocity [rad/s]
  std::vector<Vec3> force;    ///< force accumulator of the current step [N]
  std::vector<Vec3> torque;   ///< torque accumulator of the current step [N m]
  /// Force of the gas on the parcel (drag + pressure gradient) [N], set by the CFD-DEM coupling once
  /// per coupling step and added in every DEM force gather; zero without gas.
  std::vector<Vec3> fluid_force;
  std::vector<double> radius; ///< [m] (parcel radius cg r_P for coarse-grained parcels)
  std::vector<double> mass;   ///< [kg]
  std::vector<double> inv_mass;     ///< 1/m [1/kg]
  std::vector<double> inv_inertia;  ///< 1/I [1/(kg m2)]; 0 locks the rotation
  std::vector<std::uint64_t> id;    ///< identity: insertion order, kept through spatial sorts
};

}  // namespace rcfd
