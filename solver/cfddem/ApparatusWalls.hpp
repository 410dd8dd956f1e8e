#pragma once
/// \file ApparatusWalls.hpp
/// DEM walls of an apparatus: each edge of the x-y cross-section (outer polygon and draft-plate holes)
/// becomes a bounded face extruded along z, each convex corner of a wall (the four long edges of each
/// plate) an edge primitive, and z = 0, z = depth two planes. The inlet slot is permeable to gas but
/// not to particles, so it is a face like any wall; so is the outlet (particles stay in the chamber).

#include <vector>

#include "cfddem/DemWalls.hpp"
#include "geometry/Apparatus.hpp"

namespace rcfd {

/// Walls from cross-section edges (closed loops in any order and orientation; the loop of largest
/// area is the outer boundary, the others are holes) extruded over 0 <= z <= depth.
DemWalls wallsFromSection(const std::vector<SectionEdge>& edges, double depth);

/// Walls of an apparatus (uses only its cross-section and depth).
DemWalls wallsFromApparatus(const Apparatus& apparatus);

}  // namespace rcfd
