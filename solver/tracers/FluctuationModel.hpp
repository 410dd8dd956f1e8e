#pragma once
/// \file FluctuationModel.hpp
/// Magnitude of the fluctuation velocity that relaxes tracer over-packing toward alpha_P^rec
/// (Eq. 10 and its CFDEMcoupling-PFM variant), registered by name; the scene picks one with
/// rcfd.fluctuation_model. The direction (a uniform random unit vector) and the cap u_fluc_max are
/// applied by the motion kernel.

#include <algorithm>
#include <cstdint>

#include "core/Registry.hpp"

namespace rcfd {

class FluctuationModel {
 public:
  virtual ~FluctuationModel() = default;
  /// |u_fluc| [m/s] for tracer volume fraction alphaTracer and recurrence volume fraction alphaRec of
  /// the tracer's cell, diffusion coefficient d0 [m2/s] and time step dt [s]. Always finite and >= 0.
  virtual double speed(double alphaTracer, double alphaRec, double d0, double dt) const = 0;

  /// The speeds of `count` cells at once, as the motion kernel stores them once per step:
  /// out[stride c] = float(min(speed(alphaTracer[c], alphaRec[c], d0, dt), cap)) where alphaTracer[c] > 0,
  /// 0 elsewhere, with alphaRec[c] = recA[c] + blend (recB[c] - recA[c]) (recA[c] alone when recB is
  /// null). Models override it with a loop the compiler vectorises; the result must equal the
  /// per-cell one bit for bit.
  virtual void speeds(std::int64_t count, const float* alphaTracer, const float* recA, const float* recB,
                      double blend, double d0, double dt, double cap, float* out, int stride) const {
    for (std::int64_t c = 0; c < count; ++c) {
      const double rec = recB ? double(recA[c]) + blend * (double(recB[c]) - double(recA[c])) : double(recA[c]);
      out[stride * c] = alphaTracer[c] > 0.0f ? float(std::min(speed(alphaTracer[c], rec, d0, dt), cap)) : 0.0f;
    }
  }
};

using FluctuationModelRegistry = Registry<FluctuationModel>;

}  // namespace rcfd
