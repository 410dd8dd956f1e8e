// The two registered fluctuation models. Both return 0 where the tracers are not denser than the
// recurrence field, and are bounded for any input (empty and over-packed cells included).
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

#include "tracers/FluctuationModel.hpp"

namespace rcfd {
namespace {

/// Lichtenegger & Pirker (2016), the paper's Eq. (10): |u_fluc| = sqrt(D0 dalpha / (6 pi dt alpha_P)),
/// dalpha = max(0, alpha_P - alpha_P^rec). dalpha / alpha_P lies in [0, 1), so the speed never exceeds
/// sqrt(D0 / (6 pi dt)) however over-packed a cell is.
class LichteneggerPirkerFluctuation final : public FluctuationModel {
 public:
  double speed(double alphaTracer, double alphaRec, double d0, double dt) const override {
    if (!(alphaTracer > 0.0) || !(dt > 0.0) || !(d0 > 0.0)) return 0.0;
    const double excess = std::max(0.0, alphaTracer - std::max(0.0, alphaRec));
    return std::sqrt(d0 * excess / (6.0 * std::numbers::pi * dt * alphaTracer));  // Eq. (10)
  }
};

/// CFDEMcoupling-PFM's form: |u_fluc| = sqrt(6 D0 dalpha_rel / dt) with the relative deficit of the
/// gas fraction, dalpha_rel = max(0, alpha_G^rec - alpha_G) / alpha_G^rec, in [0, 1].
class CfdemFluctuation final : public FluctuationModel {
 public:
  double speed(double alphaTracer, double alphaRec, double d0, double dt) const override {
    if (!(dt > 0.0) || !(d0 > 0.0)) return 0.0;
    const double gasRec = 1.0 - std::clamp(alphaRec, 0.0, 1.0);
    const double gas = 1.0 - std::clamp(alphaTracer, 0.0, 1.0);
    if (!(gasRec > 0.0)) return 0.0;
    const double deficit = std::max(0.0, gasRec - gas) / gasRec;
    return std::sqrt(6.0 * d0 * deficit / dt);
  }
};

const bool registeredPaper = FluctuationModelRegistry::add(
    "lichtenegger_pirker", "Eq. (10): |u_fluc| = sqrt(D0 dalpha / (6 pi dt alpha_P)) (the paper)",
    [] { return std::make_unique<LichteneggerPirkerFluctuation>(); });
const bool registeredCfdem = FluctuationModelRegistry::add(
    "cfdem", "CFDEMcoupling-PFM form: |u_fluc| = sqrt(6 D0 dalpha_rel / dt), dalpha_rel on the gas fraction",
    [] { return std::make_unique<CfdemFluctuation>(); });

}  // namespace
}  // namespace rcfd
