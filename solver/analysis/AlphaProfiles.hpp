#pragma once
/// \file AlphaProfiles.hpp
/// Horizontal profiles of a time-averaged alpha_P field: at a given height, every open cell column
/// across x with the value on the mid-plane cell layer, the open-volume-weighted mean over the depth
/// and the open fraction of the mid-plane cell (which shows where the walls cut the grid). Used to
/// tell an annulus value from a spout-edge or wall-cell value (docs/database.md).

#include <string>
#include <vector>

#include "fields/FieldDatabase.hpp"
#include "scene/Scene.hpp"

namespace rcfd::analysis {

struct AlphaProfileCell {
  double x = 0.0;           ///< cell centre [m]
  double alphaMid = 0.0;    ///< alpha_P on the mid-plane layer [-]
  double alphaDepth = 0.0;  ///< sum_k phi_k alpha_k / sum_k phi_k over the column's cells [-]
  double openMid = 0.0;     ///< open fraction phi of the mid-plane cell [-]
};

struct AlphaProfile {
  double y = 0.0;  ///< centre of the cell row [m]
  std::vector<AlphaProfileCell> cells;  ///< columns whose mid-plane cell is open, increasing x
};

/// Profiles of the per-cell field `alpha` (e.g. meanAlphaP(db)) at the cell rows holding `heights`
/// [m]; heights outside the grid are skipped.
std::vector<AlphaProfile> alphaProfiles(const Scene& scene, const FieldDatabase& db, const std::vector<double>& alpha,
                                        const std::vector<double>& heights);

/// Draws the profiles (alpha_P on the mid-plane against x, one line per height, cut wall cells
/// marked, a dashed line at alpha_P = 0.5) as database_alpha_p_profiles.svg in outDir; returns the
/// file name.
std::string writeAlphaProfileFigure(const std::vector<AlphaProfile>& profiles, const std::string& outDir);

}  // namespace rcfd::analysis
