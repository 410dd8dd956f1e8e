#pragma once
/// \file DemMaterial.hpp
/// Material and contact parameters of the DEM, derived once from the scene: effective moduli of the
/// Hertz-Mindlin model, the damping factor from the coefficient of restitution, friction and rolling
/// friction, separately for particle-particle and particle-wall contacts (docs/dem.md).

#include <string>

#include "scene/Scene.hpp"

namespace rcfd {

/// Parameters of one kind of contact (particle-particle or particle-wall).
struct ContactParams {
  double y_eff = 0.0;        ///< Y*, effective Young's modulus [Pa]
  double g_eff = 0.0;        ///< G*, effective shear modulus [Pa]
  double restitution = 1.0;  ///< e [-]
  double beta = 0.0;         ///< ln(e) / sqrt(ln^2 e + pi^2) [-] (0 for e = 1)
  double friction = 0.0;     ///< Coulomb coefficient mu [-]
  double rolling = 0.0;      ///< rolling friction coefficient mu_r [-]
};

/// The material of particles and walls (one material, as in the paper: particles and walls share Y and
/// nu) and the two contact kinds.
struct DemMaterial {
  double density = 1040.0;        ///< rho_P [kg/m3]
  double youngs_modulus = 5e6;    ///< Y [Pa]
  double poisson_ratio = 0.25;    ///< nu [-]
  double particle_radius = 0.9e-3;  ///< parcel radius cg d_P / 2 [m]
  double coarse_graining = 1.0;   ///< cg [-]
  ContactParams particle_particle;
  ContactParams particle_wall;

  /// Builds the material of a scene: parcel radius cg d_P/2, Y, nu, e, mu, mu_r unchanged by cg
  /// (docs/dem.md, "Coarse graining").
  static DemMaterial fromScene(const Scene& scene);

  /// Builds a material from explicit values (tests, benchmarks); e/mu/mu_r pairs as in DemSpec.
  static DemMaterial make(double density, double youngs_modulus, double poisson_ratio, double radius,
                          const ContactPair& restitution, const ContactPair& friction,
                          const ContactPair& rolling_friction);

  /// Shear modulus G = Y / (2 (1 + nu)) [Pa].
  double shearModulus() const;
  /// Rayleigh time pi R sqrt(rho/G) / (0.1631 nu + 0.8766) of the parcel radius R [s].
  double rayleighTime() const;
};

/// beta = ln(e) / sqrt(ln^2(e) + pi^2), the damping ratio of a coefficient of restitution e in (0, 1].
double dampingRatio(double restitution);

/// Refuses a DEM time step above `max_fraction` of the Rayleigh time with rcfd::InputError naming
/// /dem/time_step and the largest allowed value; returns the fraction dt / t_R used.
double checkTimeStep(const DemMaterial& material, double dt, double max_fraction,
                     const std::string& source = "scene");

}  // namespace rcfd
