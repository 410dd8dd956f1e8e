#include "spray/DepositionEfficiency.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "scene/Scene.hpp"

namespace rcfd {

DepositionConstants depositionConstants(const Scene& scene) {
  DepositionConstants c;
  c.particleDiameter = scene.particles.diameter;
  c.dropletDiameter = scene.spray.droplet_diameter;
  c.dropletDensity = scene.spray.droplet_density;
  c.gasDensity = scene.gas.density;
  c.gasViscosity = scene.gas.kinematic_viscosity;
  return c;
}

double happelParameter(double alphaP) {
  const double a = std::clamp(alphaP, 0.0, kMaxPackingForDeposition);
  const double a13 = std::cbrt(a);
  const double a53 = a13 * a13 * a13 * a13 * a13;
  const double numerator = 6.0 - 6.0 * a53;
  const double denominator = 6.0 - 9.0 * a13 + 9.0 * a53 - 6.0 * a * a;  // Eq. (14), > 0.019 here
  return numerator / denominator;
}

double filterCoefficient(const DepositionInput& in, const DepositionConstants& c) {
  const double alphaP = std::clamp(in.alphaP, 0.0, kMaxPackingForDeposition);
  const double slip = std::max(0.0, in.slip);
  if (!(slip > 0.0) || !std::isfinite(slip)) return 0.0;
  const double alphaG = 1.0 - alphaP;
  // Impaction Stokes number (dimensionless form of the paper's St).
  const double st = c.dropletDensity * c.dropletDiameter * c.dropletDiameter * slip /
                    (9.0 * c.gasDensity * c.gasViscosity * c.particleDiameter);
  const double reM = alphaG * slip * c.particleDiameter / c.gasViscosity;                        // Re_m
  const double stEff = 0.5 * st * (happelParameter(alphaP) + 1.14 * std::pow(reM, 0.2) * std::pow(alphaG, -1.5));  // Eq. (13)
  const double s32 = std::pow(stEff, 3.2);
  if (!std::isfinite(s32)) return 1.0;  // St_eff -> infinity: lambda -> 1
  return s32 / (s32 + 4.3);  // Eq. (12)
}

namespace {

double exponent(const DepositionInput& in, const DepositionConstants& c) {
  const double alphaP = std::clamp(in.alphaP, 0.0, kMaxPackingForDeposition);
  if (!(alphaP > 0.0) || !(in.slip > 0.0) || !(in.dt > 0.0)) return 0.0;
  return 1.5 * filterCoefficient(in, c) * in.slip * alphaP * in.dt / c.particleDiameter;  // Eq. (11)
}

class ExponentialDeposition final : public DepositionModel {
 public:
  double efficiency(const DepositionInput& in, const DepositionConstants& c) const override {
    const double x = exponent(in, c);
    return std::isfinite(x) ? -std::expm1(-x) : 1.0;
  }
};

class LinearClippedDeposition final : public DepositionModel {
 public:
  double efficiency(const DepositionInput& in, const DepositionConstants& c) const override {
    const double x = exponent(in, c);
    return std::isfinite(x) ? std::min(1.0, x) : 1.0;
  }
};

const bool exponentialRegistered = DepositionModelRegistry::add(
    "exponential", "eta = 1 - exp(-1.5 lambda |u_G - u_P| alpha_P dt / d_P): Eq. (11) for small eta, in [0, 1]",
    [] { return std::make_unique<ExponentialDeposition>(); });
const bool linearRegistered = DepositionModelRegistry::add(
    "linear_clipped", "Eq. (11) as printed, clipped to 1",
    [] { return std::make_unique<LinearClippedDeposition>(); });

}  // namespace
}  // namespace rcfd
