// The two registered fluctuation models. Both return 0 where the tracers are not denser than the
// recurrence field, and are bounded for any input (empty and over-packed cells included).
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

#include "tracers/FluctuationModel.hpp"

namespace rcfd {
namespace {

// The models' formulas as plain inline functions, shared by speed() and the vectorised speeds().

/// Lichtenegger & Pirker (2016), the paper's Eq. (10): |u_fluc| = sqrt(D0 dalpha / (6 pi dt alpha_P)),
/// dalpha = max(0, alpha_P - alpha_P^rec). dalpha / alpha_P lies in [0, 1), so the speed never exceeds
/// sqrt(D0 / (6 pi dt)) however over-packed a cell is.
inline double lichteneggerPirkerSpeed(double alphaTracer, double alphaRec, double d0, double dt) {
  // Without branches (selects), so that speedsOf() vectorises.
  const bool defined = (alphaTracer > 0.0) & (dt > 0.0) & (d0 > 0.0);  // & not &&: no branches
  const double rec = alphaRec > 0.0 ? alphaRec : 0.0;
  const double excess = alphaTracer - rec > 0.0 ? alphaTracer - rec : 0.0;
  const double v = std::sqrt(d0 * excess / (6.0 * std::numbers::pi * dt * alphaTracer));  // Eq. (10)
  return defined ? v : 0.0;
}

/// CFDEMcoupling-PFM's form: |u_fluc| = sqrt(6 D0 dalpha_rel / dt) with the relative deficit of the
/// gas fraction, dalpha_rel = max(0, alpha_G^rec - alpha_G) / alpha_G^rec, in [0, 1].
inline double cfdemSpeed(double alphaTracer, double alphaRec, double d0, double dt) {
  const double gasRec = 1.0 - (alphaRec < 0.0 ? 0.0 : (alphaRec > 1.0 ? 1.0 : alphaRec));
  const double gas = 1.0 - (alphaTracer < 0.0 ? 0.0 : (alphaTracer > 1.0 ? 1.0 : alphaTracer));
  const bool defined = (dt > 0.0) & (d0 > 0.0) & (gasRec > 0.0);
  const double deficit = (gasRec - gas > 0.0 ? gasRec - gas : 0.0) / gasRec;
  const double v = std::sqrt(6.0 * d0 * deficit / dt);
  return defined ? v : 0.0;
}

/// speeds() of FluctuationModel for a model's formula, in a loop the compiler vectorises.
template <double (*Speed)(double, double, double, double)>
void speedsOf(std::int64_t count, const float* alphaTracer, const float* recA, const float* recB, double blend,
              double d0, double dt, double cap, float* out, int stride) {
  // Every lane computed, then selected: GCC does not speculate a conditional conversion to float, so
  // the cap is applied after rounding (the same float: rounding preserves order).
  const float capF = float(cap);
  if (recB) {
#pragma omp simd
    for (std::int64_t c = 0; c < count; ++c) {
      const double rec = double(recA[c]) + blend * (double(recB[c]) - double(recA[c]));
      const float v = float(Speed(alphaTracer[c], rec, d0, dt));
      out[stride * c] = alphaTracer[c] > 0.0f ? (v < capF ? v : capF) : 0.0f;
    }
  } else {
#pragma omp simd
    for (std::int64_t c = 0; c < count; ++c) {
      const float v = float(Speed(alphaTracer[c], double(recA[c]), d0, dt));
      out[stride * c] = alphaTracer[c] > 0.0f ? (v < capF ? v : capF) : 0.0f;
    }
  }
}

class LichteneggerPirkerFluctuation final : public FluctuationModel {
 public:
  double speed(double alphaTracer, double alphaRec, double d0, double dt) const override {
    return lichteneggerPirkerSpeed(alphaTracer, alphaRec, d0, dt);
  }
  void speeds(std::int64_t count, const float* alphaTracer, const float* recA, const float* recB, double blend,
              double d0, double dt, double cap, float* out, int stride) const override {
    speedsOf<lichteneggerPirkerSpeed>(count, alphaTracer, recA, recB, blend, d0, dt, cap, out, stride);
  }
};

class CfdemFluctuation final : public FluctuationModel {
 public:
  double speed(double alphaTracer, double alphaRec, double d0, double dt) const override {
    return cfdemSpeed(alphaTracer, alphaRec, d0, dt);
  }
  void speeds(std::int64_t count, const float* alphaTracer, const float* recA, const float* recB, double blend,
              double d0, double dt, double cap, float* out, int stride) const override {
    speedsOf<cfdemSpeed>(count, alphaTracer, recA, recB, blend, d0, dt, cap, out, stride);
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
