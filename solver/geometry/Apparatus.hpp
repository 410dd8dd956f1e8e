#pragma once
/// \file Apparatus.hpp
/// The apparatus as exact walls: a 2D cross-section in the x-y plane (a polygon, with the draft plates
/// as rectangular holes) extruded along z from 0 to the depth. The same description serves the box of
/// verification cases. Used by the grid (open fractions), the DEM (particle-wall contacts), tracers
/// and droplet parcels (reflection, exit through the outlet).
///
/// Sign convention: signedDistance(p) > 0 inside the open (gas) region, < 0 inside a wall or outside
/// the apparatus; normals point from the wall into the open region.

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "geometry/CartesianGrid.hpp"
#include "scene/Scene.hpp"

namespace rcfd {

/// What a boundary is for the gas and the dispersed phases.
enum class BoundaryKind {
  Wall,    ///< solid: reflects particles, tracers; removes droplet parcels (deposit on the wall)
  Inlet,   ///< gas inlet slot at y = 0: gas enters; particles, tracers and parcels are reflected
  Outlet,  ///< top of the chamber: gas leaves; parcels leave (overspray); tracers, particles reflected
  Plate    ///< a draft plate face or edge: a wall inside the chamber
};

/// First crossing of a segment with the apparatus boundary.
struct BoundaryHit {
  double t = 0.0;                                 ///< fraction of the segment a->b where it hits [0, 1]
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< a + t (b - a) [m]
  Eigen::Vector3d normal = Eigen::Vector3d::Zero(); ///< unit normal into the open region
  BoundaryKind kind = BoundaryKind::Wall;
};

/// Nearest boundary feature of a point.
struct NearestBoundary {
  double distance = 0.0;  ///< signed distance: > 0 inside the open region [m]
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit normal into the open region
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   ///< nearest point on the boundary [m]
  BoundaryKind kind = BoundaryKind::Wall;
};

/// A polygon edge in the x-y cross-section, with its boundary kind (walls, inlet, outlet, plates).
struct SectionEdge {
  Eigen::Vector2d a, b;
  BoundaryKind kind = BoundaryKind::Wall;
};

class Apparatus {
 public:
  explicit Apparatus(const ApparatusSpec& spec);

  const ApparatusSpec& spec() const { return spec_; }

  /// Axis-aligned bounding box of the open region [m].
  Eigen::Vector3d lowerCorner() const;
  Eigen::Vector3d upperCorner() const;
  double depth() const;

  bool contains(const Eigen::Vector3d& p) const;
  double signedDistance(const Eigen::Vector3d& p) const;
  NearestBoundary nearestBoundary(const Eigen::Vector3d& p) const;

  /// First boundary the segment a->b crosses (a must be inside), or nothing if b is reachable.
  std::optional<BoundaryHit> firstIntersection(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;

  /// Exact open volume of the chamber [m3] (cross-section area times depth).
  double openVolume() const;
  /// Area of the x-y cross-section's open region [m2].
  double sectionArea() const;

  /// The cross-section's outer boundary (counter-clockwise) and plate outlines, for drawing.
  const std::vector<SectionEdge>& sectionEdges() const { return edges_; }

 private:
  ApparatusSpec spec_;
  std::vector<Eigen::Vector2d> outline_;               ///< counter-clockwise outer polygon
  std::vector<std::vector<Eigen::Vector2d>> holes_;    ///< plates, each a rectangle
  std::vector<SectionEdge> edges_;
};

/// The uniform grid of a scene over the apparatus's bounding box (cell size from the scene, rounded so
/// that a whole number of cells spans each extent).
CartesianGrid makeGrid(const Apparatus& apparatus, const GridSpec& spec);

/// Open volume fraction of every cell (C order, x fastest), in [0, 1], from exact clipping of the
/// cross-section against each cell.
std::vector<double> openFractions(const Apparatus& apparatus, const CartesianGrid& grid);

}  // namespace rcfd
