#pragma once
/// \file OpenFoamImport.hpp
/// An OpenFOAM case (docs/import.md) turned into an rcfd field database: one frame per written time
/// (evenly spaced: dt_rec is their spacing) on the scene's grid (CartesianMapping.hpp), and, from a
/// Lagrangian cloud, the spray-zone holdup and (where parcels carry origId/origProcId) every completed
/// stay in the spray zone under /reference/, as the database job writes them (docs/formats.md,
/// "Reference series"), so a calibration compares against the OpenFOAM run. Shared by
/// `rcfd-solve import-openfoam` and the `import` job kind.

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/CartesianGrid.hpp"
#include "import/OpenFoamCase.hpp"
#include "scene/Scene.hpp"

namespace rcfd::openfoam {

struct ImportOptions {
  std::string caseDir;
  std::string databasePath;  ///< written through DB.partial and renamed when complete
  TimeRange times;
  std::string cloud;         ///< empty: the case's only cloud
  /// Write the particles' velocity spread with every frame (a Lagrangian cloud only): what the scene's
  /// tracer effects read when TracerEffectRegistry::needsVelocitySpread() says so.
  bool velocitySpread = false;
  /// Polled between frames; true ends the import with rcfd::Cancelled (nothing is kept).
  std::function<bool()> stopRequested = {};
  /// Called after each frame with the fraction of frames done.
  std::function<void(double)> progress = {};
};

struct ImportResult {
  nlohmann::json summary;            ///< what was read and how it mapped (docs/import.md)
  std::vector<double> alphaPMean;    ///< alpha_P averaged over the frames, per grid cell
  CartesianGrid grid;                ///< the scene's grid the frames are on
};

/// Imports the case; rcfd::InputError naming the file, field or time when the case cannot be read or
/// does not fit the scene, rcfd::Cancelled when stopRequested says so.
ImportResult importOpenFoam(const Scene& scene, const ImportOptions& options);

}  // namespace rcfd::openfoam
