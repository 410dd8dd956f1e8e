#pragma once
/// \file DragModel.hpp
/// Drag laws of the CFD-DEM coupling, selected by the scene's `gas.drag_model` (rcfd::Registry, like the
/// contact models; the schema's enum lists the registered names). A law gives the dimensionless drag
/// F(eps, Re) normalised by the Stokes drag of the superficial slip,
///   F_drag = 3 pi mu d eps F(eps, Re) (u_G - v)   (one primary particle of diameter d),
/// with eps the gas fraction, u_G the interstitial gas velocity and Re = d eps |u_G - v| / nu_G. A
/// coarse-grained parcel of cg^3 primary particles takes cg^3 times this force with Re on the primary
/// diameter (docs/physics.md, "CFD-DEM coupling").

#include <memory>
#include <string>

#include "core/Registry.hpp"
#include "scene/Scene.hpp"

namespace rcfd::coupling {

class DragModel {
 public:
  virtual ~DragModel() = default;
  virtual std::string name() const = 0;
  /// F(eps, Re) [-] for eps in (0, 1], Re >= 0.
  virtual double normalisedDrag(double eps, double re) const = 0;
};

using DragModelRegistry = Registry<DragModel, const Scene&>;

/// Beetstra, van der Hoef & Kuipers (2007), monodisperse form (docs/physics.md):
/// F = 10 phi / eps^2 + eps^2 (1 + 1.5 sqrt(phi))
///   + [0.413 Re / (24 eps^2)] [1/eps + 3 eps phi + 8.4 Re^-0.343] / [1 + 10^(3 phi) Re^(-(1 + 4 phi)/2)],
/// phi = 1 - eps. Its Re -> 0 limit is the Carman-Kozeny law (180 phi^2 / eps^3 in the pressure drop).
double beetstraDrag(double eps, double re);

}  // namespace rcfd::coupling
