#pragma once
/// \file WallClearance.hpp
/// Per-cell lower bounds on the distance to the apparatus's boundaries, which let movers (tracers,
/// droplet parcels) skip the exact segment test for short moves: a move shorter than the bound of the
/// cell it starts in reaches no wall, plate or outlet.

#include <vector>

#include "geometry/Apparatus.hpp"
#include "geometry/CartesianGrid.hpp"

namespace rcfd {

/// Per cell, max(0, sd(centre) - margin) [m] rounded down to float (times 1 - 1e-6, which covers the
/// rounding to float and of the distances), sd the apparatus's signed distance. With margin at least
/// half a cell diagonal the bound holds from any point of the cell (signed distances are 1-Lipschitz);
/// add 2 boundaryTolerance() to stay clear of the band in which firstIntersection() reports hits.
std::vector<float> cellWallClearance(const Apparatus& apparatus, const CartesianGrid& grid, double margin);

}  // namespace rcfd
