#pragma once
/// \file WallClearance.hpp
/// Per-cell lower bounds on the distance to the apparatus's boundaries, which let movers (tracers,
/// droplet parcels) skip the exact segment test for short moves: a move shorter than the bound of the
/// cell it starts in reaches no wall, plate or outlet.

#include <cstdint>
#include <vector>

#include "geometry/Apparatus.hpp"
#include "geometry/CartesianGrid.hpp"

namespace rcfd {

/// Per cell, max(0, sd(centre) - margin) [m] rounded down to float (times 1 - 1e-6, which covers the
/// rounding to float and of the distances), sd the apparatus's signed distance. With margin at least
/// half a cell diagonal the bound holds from any point of the cell (signed distances are 1-Lipschitz);
/// add 2 boundaryTolerance() to stay clear of the band in which firstIntersection() reports hits.
std::vector<float> cellWallClearance(const Apparatus& apparatus, const CartesianGrid& grid, double margin);

/// Per cell, a bit mask of the half-spaces (n . p >= c, e.g. Apparatus::convexHalfSpaces(), at most 32)
/// that a short move from the cell may come within `margin` of: bit j is clear only if every point p
/// of the cell moved by any d with |d| <= reach ends at n_j . (p + d) - c_j >= margin. Points are taken
/// within half a cell diagonal of the centre (signed distances to a plane are 1-Lipschitz), with a slack
/// of 1e-6 of the smallest spacing over the rounding of the plane distances, so a test of a clear bit
/// evaluated in double would pass too: skipping it changes no decision. 32 bits per cell: the motion
/// kernel gathers them a vector at a time (bytes have no vector gather).
std::vector<std::uint32_t> nearHalfSpaceMasks(const std::vector<Apparatus::HalfSpace>& halfSpaces,
                                              const CartesianGrid& grid, double margin, double reach);

}  // namespace rcfd
