#include "cfddem/DemParticles.hpp"

#include <numbers>

#include "core/Permutation.hpp"

namespace rcfd {

std::size_t DemParticles::add(const Vec3& pos, const Vec3& vel, double r, double density) {
  const double m = 4.0 / 3.0 * std::numbers::pi * r * r * r * density;
  x.push_back(pos);
  v.push_back(vel);
  omega.push_back(Vec3::Zero());
  force.push_back(Vec3::Zero());
  torque.push_back(Vec3::Zero());
  fluid_force.push_back(Vec3::Zero());
  radius.push_back(r);
  mass.push_back(m);
  inv_mass.push_back(1.0 / m);
  inv_inertia.push_back(1.0 / (0.4 * m * r * r));
  id.push_back(id.size());
  return x.size() - 1;
}

void DemParticles::permute(const std::vector<std::size_t>& perm) {
  applyPermutation(x, perm); applyPermutation(v, perm); applyPermutation(omega, perm);
  applyPermutation(force, perm); applyPermutation(torque, perm); applyPermutation(radius, perm);
  applyPermutation(fluid_force, perm);
  applyPermutation(mass, perm); applyPermutation(inv_mass, perm); applyPermutation(inv_inertia, perm);
  applyPermutation(id, perm);
}

void DemParticles::reserve(std::size_t n) {
  id.reserve(n);
  x.reserve(n); v.reserve(n); omega.reserve(n); force.reserve(n); torque.reserve(n); fluid_force.reserve(n);
  radius.reserve(n); mass.reserve(n); inv_mass.reserve(n); inv_inertia.reserve(n);
}

double DemParticles::kineticEnergy() const {
  double e = 0.0;
  for (std::size_t i = 0; i < size(); ++i) {
    e += 0.5 * mass[i] * v[i].squaredNorm();
    if (inv_inertia[i] > 0.0) e += 0.5 * omega[i].squaredNorm() / inv_inertia[i];
  }
  return e;
}

double DemParticles::gravityPotential(const Vec3& gravity) const {
  double e = 0.0;
  for (std::size_t i = 0; i < size(); ++i) e -= mass[i] * gravity.dot(x[i]);
  return e;
}

}  // namespace rcfd
