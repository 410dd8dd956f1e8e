#include "cfddem/DemMaterial.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "core/Errors.hpp"

namespace rcfd {

double dampingRatio(double e) {
  if (e >= 1.0) return 0.0;
  const double le = std::log(e);
  return le / std::sqrt(le * le + std::numbers::pi * std::numbers::pi);
}

namespace {
ContactParams makeParams(double y, double nu, double e, double mu, double mu_r) {
  // Both bodies of the same material: 1/Y* = 2 (1 - nu^2)/Y, 1/G* = 2 * 2 (2 - nu)(1 + nu)/Y
  // (Hertz; Mindlin with G = Y / (2 (1 + nu))), as LIGGGHTS' Yeff/Geff for two equal materials.
  ContactParams p;
  p.y_eff = y / (2.0 * (1.0 - nu * nu));
  p.g_eff = y / (4.0 * (2.0 - nu) * (1.0 + nu));
  p.restitution = e;
  p.beta = dampingRatio(e);
  p.friction = mu;
  p.rolling = mu_r;
  return p;
}
}  // namespace

DemMaterial DemMaterial::make(double density, double y, double nu, double radius,
                              const ContactPair& e, const ContactPair& mu, const ContactPair& mu_r) {
  DemMaterial m;
  m.density = density;
  m.youngs_modulus = y;
  m.poisson_ratio = nu;
  m.particle_radius = radius;
  m.particle_particle = makeParams(y, nu, e.particle_particle, mu.particle_particle,
                                   mu_r.particle_particle);
  m.particle_wall = makeParams(y, nu, e.particle_wall, mu.particle_wall, mu_r.particle_wall);
  return m;
}

DemMaterial DemMaterial::fromScene(const Scene& scene) {
  const double cg = scene.dem.coarse_graining;
  // Coarse graining (Radl et al. 2011): a parcel is a sphere of cg times the radius with the same
  // density, Y, nu, e, mu and mu_r; with the Hertz law this keeps delta/R, e and the friction angle.
  DemMaterial m = make(scene.particles.density, scene.particles.youngs_modulus,
                       scene.particles.poisson_ratio, 0.5 * cg * scene.particles.diameter,
                       scene.dem.restitution, scene.dem.friction, scene.dem.rolling_friction);
  m.coarse_graining = cg;
  return m;
}

double DemMaterial::shearModulus() const { return youngs_modulus / (2.0 * (1.0 + poisson_ratio)); }

double DemMaterial::rayleighTime() const {
  return std::numbers::pi * particle_radius * std::sqrt(density / shearModulus()) /
         (0.1631 * poisson_ratio + 0.8766);
}

double checkTimeStep(const DemMaterial& material, double dt, double max_fraction,
                     const std::string& source) {
  const double t_r = material.rayleighTime();
  const double fraction = dt / t_r;
  if (!(dt > 0.0) || fraction > max_fraction) {
    std::ostringstream msg;
    msg.precision(4);
    msg << dt << " s is " << fraction << " of the Rayleigh time " << t_r << " s (parcel radius "
        << material.particle_radius << " m); /dem/max_rayleigh_fraction " << max_fraction
        << " allows at most " << max_fraction * t_r << " s";
    if (!(dt > 0.0)) msg << "; the time step must be positive";
    throw InputError(source, "/dem/time_step", msg.str());
  }
  return fraction;
}

}  // namespace rcfd
