#pragma once
/// \file FluctuationModel.hpp
/// Magnitude of the fluctuation velocity that relaxes tracer over-packing toward alpha_P^rec
/// (Eq. 10 and its CFDEMcoupling-PFM variant), registered by name; the scene picks one with
/// rcfd.fluctuation_model. The direction (a uniform random unit vector) and the cap u_fluc_max are
/// applied by the motion kernel.

#include "core/Registry.hpp"

namespace rcfd {

class FluctuationModel {
 public:
  virtual ~FluctuationModel() = default;
  /// |u_fluc| [m/s] for tracer volume fraction alphaTracer and recurrence volume fraction alphaRec of
  /// the tracer's cell, diffusion coefficient d0 [m2/s] and time step dt [s]. Always finite and >= 0.
  virtual double speed(double alphaTracer, double alphaRec, double d0, double dt) const = 0;
};

using FluctuationModelRegistry = Registry<FluctuationModel>;

}  // namespace rcfd
