#pragma once
/// \file Apparatus.hpp
/// The apparatus as exact walls: a 2D cross-section in the x-y plane (a polygon, with the draft plates
/// as rectangular holes) extruded along z from 0 to the depth. The same description serves the box of
/// verification cases. Used by the grid (open fractions), the DEM (particle-wall contacts), tracers
/// and droplet parcels (reflection, exit through the outlet).
///
/// Sign convention: signedDistance(p) > 0 inside the open (gas) region, < 0 inside a wall or outside
/// the apparatus; normals point from the wall into the open region. Points on the boundary count as
/// inside (contains() is true, signedDistance() is 0).
///
/// Tolerance contract of firstIntersection(): hits are reported against the open region shrunk by
/// boundaryTolerance() (about 1e-9 of the apparatus size, i.e. sub-nanometre), so a reported hit point
/// lies inside the open region, at most ~2 boundaryTolerance() from the wall it hit (signedDistance of
/// the hit point >= 0 up to round-off of ~1e-16 m). A segment that starts inside that thin band and
/// moves towards the wall gets a hit at t = 0 (point = a); one that moves parallel to or away from the
/// wall gets none from that wall (a motion that leaves the wall's plane by less than ~1e-15 of the
/// apparatus size counts as parallel: round-off, and its end point is at most that far outside). So
/// the usual loop
///
///   while (auto hit = apparatus.firstIntersection(a, b)) {        // cap the number of bounces
///     const Vector3d rest = b - hit->point;
///     a = hit->point; b = a + rest - 2 * rest.dot(hit->normal) * hit->normal;   // mirror
///   }
///
/// never leaves the apparatus: every a it produces is a reported hit point, and a segment without a hit
/// stays in the open region from a to b. Features thinner than the tolerance are inflated by it: a
/// segment passing a draft plate's tip at less than boundaryTolerance() counts as a hit on the plate.

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
  /// Builds the walls; throws rcfd::InputError naming the JSON pointer (e.g.
  /// "/apparatus/draft_plates/elevation") when the dimensions are inconsistent: non-positive sizes, an
  /// inlet at least as wide as the chamber, a chamber not taller than the V, plates that do not fit.
  explicit Apparatus(const ApparatusSpec& spec);

  const ApparatusSpec& spec() const { return spec_; }

  /// Axis-aligned bounding box of the open region [m].
  Eigen::Vector3d lowerCorner() const;
  Eigen::Vector3d upperCorner() const;
  double depth() const;

  bool contains(const Eigen::Vector3d& p) const;
  double signedDistance(const Eigen::Vector3d& p) const;
  NearestBoundary nearestBoundary(const Eigen::Vector3d& p) const;

  /// First boundary the segment a->b crosses, or nothing if the whole segment stays in the open region
  /// (then b is inside). `a` must be inside or on the boundary (signedDistance(a) >= -boundaryTolerance());
  /// for a start point farther outside the result is unspecified: project it back first with
  /// nearestBoundary(). Allocation-free. See the file comment for the tolerance contract.
  std::optional<BoundaryHit> firstIntersection(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const;

  /// A half-space n . p - c >= 0 bounding the open region.
  struct HalfSpace {
    Eigen::Vector3d n;  ///< unit inward normal
    double c = 0.0;     ///< [m]
  };
  /// The half-spaces whose intersection is the open region without the draft plates: one per edge of
  /// the (convex) outline, then the walls z = 0 and z = depth. A segment from an admissible start
  /// (see firstIntersection()) whose end lies at least 2 boundaryTolerance() inside every one of them,
  /// and which misses the plates, has no hit in firstIntersection(): the vectorised tracer kernel's
  /// wall test.
  std::vector<HalfSpace> convexHalfSpaces() const;

  /// Width of the band inside the walls in which firstIntersection() reports hits [m].
  double boundaryTolerance() const { return tol_; }

  /// prismatic_spouted_bed: height y_v where the V walls meet the vertical side walls,
  /// (width - inlet_width) / 2 * tan(prism angle) [m]; box: 0.
  double vWallTop() const { return yV_; }
  /// Height of the chamber floor (the V walls, the inlet, or the box bottom) at lateral position x [m].
  double floorHeight(double x) const;

  /// Exact open volume of the chamber [m3] (cross-section area times depth).
  double openVolume() const;
  /// Area of the x-y cross-section's open region [m2].
  double sectionArea() const;

  /// The cross-section's outer boundary (counter-clockwise) and plate outlines, for drawing.
  const std::vector<SectionEdge>& sectionEdges() const { return edges_; }
  /// The outer polygon (counter-clockwise; convex for both apparatus types) [m].
  const std::vector<Eigen::Vector2d>& outline() const { return outline_; }
  /// The draft plates' rectangles (clockwise, so the open region is on the left of every edge) [m].
  const std::vector<std::vector<Eigen::Vector2d>>& holes() const { return holes_; }

 private:
  /// One edge of the convex outline as a half-plane: n . p - c >= 0 inside, n the unit inward normal.
  struct HalfPlane {
    Eigen::Vector2d n;
    double c = 0.0;
    BoundaryKind kind = BoundaryKind::Wall;
  };
  /// A draft plate: an axis-aligned rectangle spanning the whole depth.
  struct PlateBox {
    Eigen::Vector2d lo, hi;
  };
  /// Signed 2D distance to the cross-section (> 0 inside) with the nearest point, normal and kind.
  double section2d(const Eigen::Vector2d& p, Eigen::Vector2d& q, Eigen::Vector2d& n,
                   BoundaryKind& kind) const;

  ApparatusSpec spec_;
  std::vector<Eigen::Vector2d> outline_;               ///< counter-clockwise outer polygon
  std::vector<std::vector<Eigen::Vector2d>> holes_;    ///< plates, each a rectangle
  std::vector<SectionEdge> edges_;
  std::vector<HalfPlane> planes_;  ///< one per outline edge, same order
  std::vector<PlateBox> plates_;
  double depth_ = 0.0;
  double yV_ = 0.0;
  double tol_ = 0.0;
  double noise_ = 0.0;  ///< round-off of coordinate differences: outward motion below this is parallel
  double sectionArea_ = 0.0;
  Eigen::Vector2d lo2_ = Eigen::Vector2d::Zero(), hi2_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d platesLo_ = Eigen::Vector2d::Zero(), platesHi_ = Eigen::Vector2d::Zero();
};

/// Outcome of moveWithMirrorReflection().
struct ReflectedMove {
  Eigen::Vector3d end = Eigen::Vector3d::Zero();  ///< final position, inside or on the boundary [m]
  int bounces = 0;                                ///< boundary hits on the way
  bool capped = false;  ///< stopped at the last hit point after maxBounces hits (end is still inside)
};

/// Moves a point from a towards b, mirror-reflecting the rest of the displacement at every boundary
/// (walls, plates, inlet and outlet alike): the loop of the Apparatus file comment. `a` must be inside
/// or on the boundary; the end point always is. Allocation-free.
ReflectedMove moveWithMirrorReflection(const Apparatus& apparatus, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, int maxBounces = 64);

/// The uniform grid of a scene over the apparatus's bounding box (cell size from the scene, rounded so
/// that a whole number of cells spans each extent: n = max(1, round(extent / cell_size))).
/// Throws rcfd::InputError (/grid/cell_size) for a non-positive or non-finite cell size.
CartesianGrid makeGrid(const Apparatus& apparatus, const GridSpec& spec);

/// Open volume fraction of every cell (C order, x fastest), in [0, 1], from exact clipping of the
/// cross-section against each cell.
std::vector<double> openFractions(const Apparatus& apparatus, const CartesianGrid& grid);

}  // namespace rcfd
