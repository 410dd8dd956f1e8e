#pragma once
/// \file FaceApertures.hpp
/// Open-area fractions of the faces of a uniform Cartesian grid, from exact clipping of the apparatus's
/// cross-section along each face (the walls are extruded along z, so every face is an axis-aligned
/// segment of the x-y section times a z-extent). Used by the staggered gas solver: the volume flux
/// through a face is area * aperture * alpha_G * u, which makes the discrete mass balance exact in cut
/// cells.

#include <array>
#include <vector>

#include "geometry/Apparatus.hpp"
#include "geometry/CartesianGrid.hpp"
#include "geometry/ThinWalls.hpp"

namespace rcfd::gas {

/// Open fraction [0, 1] of every face normal to each axis. Face arrays of axis d have the shape of the
/// cells plus one along d, stored x fastest: index = (k * nyF + j) * nxF + i. Faces on the grid's outer
/// boundary are open where the apparatus boundary there is an inlet or an outlet (the slot at y = 0,
/// the top), zero elsewhere (walls, including the front and back walls at z = 0 and z = depth). Plates
/// thinner than a cell close their nearest face as baffles (ThinWalls.hpp): their covered fraction is
/// taken off that face's aperture.
struct FaceApertures {
  std::array<std::array<int, 3>, 3> shape{};  ///< per axis d: face counts (nx + [d==0], ...)
  std::array<std::vector<double>, 3> open;    ///< per axis d: aperture of each face [-]
  BaffleFaces baffles;                        ///< the thin-wall baffles included in `open`
};

FaceApertures computeFaceApertures(const Apparatus& apparatus, const CartesianGrid& grid);

/// Length of the open part of the axis-aligned segment a->b of the cross-section (inside the outline,
/// outside the plates) [m]. A segment lying on a wall line counts as open (the cells beside decide).
double openSegmentLength(const Apparatus& apparatus, const Eigen::Vector2d& a, const Eigen::Vector2d& b);

}  // namespace rcfd::gas
