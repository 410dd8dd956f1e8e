#pragma once
/// \file ThinWalls.hpp
/// Walls thinner than a cell as zero-thickness baffles on grid faces. A draft plate whose extent along
/// x (or y) lies inside one cell column, with no grid face strictly inside it, removes volume from its
/// cells (openFractions) but meets no face, so per-cell open fractions alone let gas, mapped particle
/// volume and smoothing pass straight through it. As CFD codes do with baffles (OpenFOAM's
/// createBaffles turns internal faces into wall faces on both sides), such a plate is snapped to the
/// grid face nearest to its mid-plane (an exact tie goes to the lower face) and covers that face over its extent
/// along the other axis. Plates that contain a face already close it (FaceApertures), so they give no
/// baffle here. The plates span the whole depth: baffles are x- and y-faces only.
///
/// Snapping leaves a strip of the plate's cell column between the plate and the baffle face on the
/// baffle's wrong side: a particle there lies beyond the plate, but its cell is on this side of the
/// baffle. A point in the strip belongs to the cell across the face (BaffleFaces::homeCell): the
/// database's mapping puts such a particle's volume there.

#include <array>
#include <cstdint>
#include <vector>

#include "geometry/Apparatus.hpp"
#include "geometry/CartesianGrid.hpp"

namespace rcfd {

/// The strip between a snapped plate and its baffle face: points with x[axis] in (from, to) and
/// x[across] in (acrossFrom, acrossTo) belong to the cell `shift` (+-1) cells along `axis` from theirs.
struct BaffleStrip {
  int axis = 0;
  double from = 0.0, to = 0.0;              ///< [m] along axis
  double acrossFrom = 0.0, acrossTo = 0.0;  ///< [m] along the other axis of the section
  int shift = 0;
};

/// Per grid face, the fraction of its area covered by a baffle [0, 1]. Face arrays of axis d have the
/// shape of the cells plus one along d, x fastest (the layout of gas::FaceApertures). Empty arrays when
/// the apparatus has no wall thinner than a cell (the common case costs nothing).
struct BaffleFaces {
  std::array<std::array<int, 3>, 3> shape{};  ///< per axis d: face counts (nx + [d==0], ...)
  std::array<std::vector<double>, 3> covered;  ///< per axis d: covered fraction of each face [-]
  std::vector<BaffleStrip> strips;             ///< one per snapped plate

  bool empty() const { return covered[0].empty() && covered[1].empty(); }
  std::size_t index(int d, int i, int j, int k) const {
    const auto& s = shape[std::size_t(d)];
    return (std::size_t(k) * s[1] + j) * s[0] + i;
  }
  /// True when the face of axis d at face index (i, j, k) is wholly covered: nothing crosses it. An index
  /// outside the face array (a stencil reaching past the domain's edge) is no baffle: the outer walls
  /// are handled by the ghost cells.
  bool closes(int d, int i, int j, int k) const {
    const auto& c = covered[std::size_t(d)];
    const auto& s = shape[std::size_t(d)];
    if (c.empty() || i < 0 || j < 0 || k < 0 || i >= s[0] || j >= s[1] || k >= s[2]) return false;
    return c[index(d, i, j, k)] >= 1.0;
  }
  /// The cell (i, j, k) point x belongs to: its own cell, or for a point in a strip between a plate and
  /// its baffle face, the cell across that face, on the plate's side the point is on.
  std::array<int, 3> homeCell(const CartesianGrid& grid, const Eigen::Vector3d& x) const {
    std::array<int, 3> ijk = grid.cellOf(x);
    for (const BaffleStrip& s : strips) {
      const double along = x[s.axis], across = x[1 - s.axis];
      if (along > s.from && along < s.to && across > s.acrossFrom && across < s.acrossTo) {
        const int moved = ijk[std::size_t(s.axis)] + s.shift;
        if (moved >= 0 && moved < grid.shape[s.axis]) ijk[std::size_t(s.axis)] = moved;
      }
    }
    return ijk;
  }
};

/// The baffles of the apparatus's thin plates on grid (exact covered fractions: the plates and the
/// faces are axis-aligned).
BaffleFaces thinWallBaffles(const Apparatus& apparatus, const CartesianGrid& grid);

/// Per cell, the faces toward its +x and +y neighbours that a plate closes (plateSeparates; bits
/// kPlateAboveX, kPlateAboveY): what keeps trilinear stencils on one side of a plate
/// (tracers/Trilinear.hpp). Empty for an apparatus without plates.
inline constexpr std::uint8_t kPlateAboveX = 1, kPlateAboveY = 2;
std::vector<std::uint8_t> plateFacesAbove(const Apparatus& apparatus, const CartesianGrid& grid);

/// Whether a plate separates cell `ijk` from its neighbour along axis d (0: x, 1: y; -1 or +1 for
/// `side`) as the CFD-DEM's mapping, smoothing and gas see it: a plate that contains the face between
/// them (the face's plane within its thickness, the face's whole extent across) or a plate snapped to that face
/// (`baffles`, thinWallBaffles of the same grid). The other face of a cell column holding a plate
/// stays open. Faces normal to z never are (the plates span the depth).
bool plateSeparates(const Apparatus& apparatus, const CartesianGrid& grid, const BaffleFaces& baffles,
                    const std::array<int, 3>& ijk, int d, int side);

}  // namespace rcfd
