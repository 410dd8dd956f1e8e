#pragma once
/// \file DepositionEfficiency.hpp
/// The Kolakaluri (2013) filter model of droplet deposition on a packed or fluidised bed, the paper's
/// Eq. (11)-(14), evaluated per parcel and (sub-)step. Two registered forms of Eq. (11):
///  - "exponential" (default): eta = 1 - exp(-1.5 lambda |u_G - u_P| alpha_P dt / d_P), equal to Eq. (11)
///    for small eta and always in [0, 1];
///  - "linear_clipped": the paper's Eq. (11) as written, clipped to [0, 1] (it exceeds 1 in the dense
///    spout at dt = 5 ms).
/// The Stokes number is the impaction Stokes number St = rho_D d_D^2 |u_G - u_P| / (9 rho_G nu_G d_P),
/// which is dimensionless; the paper's printed form (with rho_P and without rho_G) is not
/// (docs/physics.md).

#include "core/Registry.hpp"

namespace rcfd {

/// Inputs of Eq. (11)-(14) for one parcel in one cell.
struct DepositionInput {
  double alphaP = 0.0;       ///< tracer (particle) volume fraction of the cell [-]
  double slip = 0.0;         ///< |u_G^rec - u_P^rec| [m/s]
  double dt = 0.0;           ///< time over which the parcel is exposed [s]
};

struct Scene;

/// Material constants of Eq. (11)-(14).
struct DepositionConstants {
  double particleDiameter = 1.8e-3;  ///< d_P [m]
  double dropletDiameter = 40e-6;    ///< d_D [m]
  double dropletDensity = 1000.0;    ///< rho_D [kg/m3]
  double gasDensity = 1.225;         ///< rho_G [kg/m3]
  double gasViscosity = 1.5e-5;      ///< nu_G [m2/s]
};

/// The constants of a scene: its particles', droplets' and gas's.
DepositionConstants depositionConstants(const Scene& scene);

/// Largest alpha_P the correlation is evaluated at: the densest packing of equal spheres (FCC/HCP,
/// pi / (3 sqrt 2) = 0.7405; random close packing is about 0.64); denser cells (tracer over-packing)
/// use this value. A's denominator is positive up to it (Eq. 14).
inline constexpr double kMaxPackingForDeposition = 0.74;

/// Eq. (14): Happel's parameter A(alpha_P), for alpha_P in [0, kMaxPackingForDeposition].
double happelParameter(double alphaP);
/// Eq. (12)-(13): filter coefficient lambda in [0, 1).
double filterCoefficient(const DepositionInput& in, const DepositionConstants& c);

class DepositionModel {
 public:
  virtual ~DepositionModel() = default;
  /// Fraction of a parcel's droplets deposited in one exposure, in [0, 1]; 0 for no slip or no particles.
  virtual double efficiency(const DepositionInput& in, const DepositionConstants& c) const = 0;
};

using DepositionModelRegistry = Registry<DepositionModel>;

}  // namespace rcfd
