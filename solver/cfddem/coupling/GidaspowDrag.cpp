// The drag laws "wen_yu" and "gidaspow" (DragModel.hpp), the classical closures of two-fluid and
// CFD-DEM codes (MFIX, CFDEMcoupling's GidaspowDrag), for comparison with the default "beetstra".
//
// In the literature they are momentum exchange coefficients beta [kg/(m3 s)] per unit volume, with
// eps = alpha_G, w = |u_G - v| and Re = eps rho_G d w / mu_G (Gidaspow's Re_s, the Re of DragModel.hpp):
//
//   Wen & Yu (1966):  beta = 3/4 Cd eps (1 - eps) rho_G w / d eps^-2.65,
//                     Cd = 24 / Re (1 + 0.15 Re^0.687) for Re < 1000, 0.44 otherwise
//                     (Schiller & Naumann's single-sphere drag);
//   Ergun (1952):     beta = 150 (1 - eps)^2 mu_G / (eps d^2) + 1.75 (1 - eps) rho_G w / d;
//   Gidaspow (1994):  Ergun for eps < 0.8, Wen & Yu for eps >= 0.8
//                     (D. Gidaspow, Multiphase Flow and Fluidization, Academic Press, 1994).
//
// A particle takes beta V_p / (1 - eps) of the slip, and DragModel.hpp writes that force as
// 3 pi mu_G d eps F (u_G - v), so F = beta d^2 / (18 mu_G eps (1 - eps)):
//
//   F_WenYu = Cd Re / 24 eps^-3.65,    F_Ergun = (150 (1 - eps) + 1.75 Re) / (18 eps^2).
//
// F_WenYu tends to Stokes' F = 1 for a lone sphere at Re -> 0. Gidaspow's F jumps at eps = 0.8 (Ergun
// 15% above Wen & Yu at Re -> 0, 5% at Re = 10), the known price of joining the two correlations.

#include <cmath>

#include "cfddem/coupling/DragModel.hpp"

namespace rcfd::coupling {
namespace {

/// Below this gas fraction Gidaspow's law is Ergun's packed-bed correlation.
constexpr double kGidaspowSwitch = 0.8;
/// Above this Re the single-sphere drag coefficient is Newton's constant 0.44.
constexpr double kNewtonRegimeRe = 1000.0;

double wenYu(double eps, double re) {
  const double cdRe24 = re < kNewtonRegimeRe ? 1.0 + 0.15 * std::pow(re, 0.687) : 0.44 * re / 24.0;  // Cd Re / 24
  return cdRe24 * std::pow(eps, -3.65);
}

double ergun(double eps, double re) { return (150.0 * (1.0 - eps) + 1.75 * re) / (18.0 * eps * eps); }

class WenYuDrag final : public DragModel {
 public:
  std::string name() const override { return "wen_yu"; }
  double normalisedDrag(double eps, double re) const override { return wenYu(eps, re); }
};

class GidaspowDrag final : public DragModel {
 public:
  std::string name() const override { return "gidaspow"; }
  double normalisedDrag(double eps, double re) const override {
    return eps < kGidaspowSwitch ? ergun(eps, re) : wenYu(eps, re);
  }
};

const bool wenYuRegistered = DragModelRegistry::add(
    "wen_yu", "Wen & Yu (1966): Schiller-Naumann drag times alpha_G^-3.65, at every alpha_G",
    [](const Scene&) { return std::make_unique<WenYuDrag>(); });

const bool gidaspowRegistered = DragModelRegistry::add(
    "gidaspow", "Gidaspow (1994): Ergun (1952) below alpha_G 0.8, Wen & Yu (1966) above",
    [](const Scene&) { return std::make_unique<GidaspowDrag>(); });

}  // namespace
}  // namespace rcfd::coupling
