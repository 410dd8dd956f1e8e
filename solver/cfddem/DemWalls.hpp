#pragma once
/// \file DemWalls.hpp
/// Walls for particle contacts as a set of primitives, each giving a nearest-point contact: bounded
/// planar faces and convex edges. A sphere in a concave corner (the V's bottom, a wall meeting the
/// inlet) touches two faces and feels both; near a convex edge (a draft plate's tip) only the edge
/// primitive acts, because a face contributes only where the centre projects inside it and an edge
/// only inside its Voronoi wedge (outside both adjacent faces). So no contact is counted twice.
/// Built for a box here and from the apparatus's cross-section in ApparatusWalls.hpp.

#include <Eigen/Core>
#include <cstddef>
#include <limits>
#include <vector>

namespace rcfd {

/// A bounded planar face: points o + a u + b w with a in [a_min, a_max], b in [b_min, b_max] (bounds
/// may be infinite); `normal` points into the open region.
struct WallFace {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();
  Eigen::Vector3d u = Eigen::Vector3d::UnitX();
  Eigen::Vector3d w = Eigen::Vector3d::UnitZ();
  double a_min = -std::numeric_limits<double>::infinity();
  double a_max = std::numeric_limits<double>::infinity();
  double b_min = -std::numeric_limits<double>::infinity();
  double b_max = std::numeric_limits<double>::infinity();
  /// Centres further behind the face than this (signed distance below it) do not touch it: half the
  /// thickness of a thin plate, so a sphere on one side never feels the opposite face [m].
  double min_distance = -std::numeric_limits<double>::infinity();
};

/// A convex edge (a line segment o + s dir, s in [0, length]) where two faces meet at an angle that
/// points into the open region; f1, f2 are the in-face directions from the edge into the two faces.
struct WallEdge {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d dir = Eigen::Vector3d::UnitZ();
  double length = 0.0;
  Eigen::Vector3d f1 = Eigen::Vector3d::UnitX();
  Eigen::Vector3d f2 = Eigen::Vector3d::UnitY();
};

/// Result of a sphere-primitive test.
struct WallContact {
  double distance = 0.0;  ///< centre to the primitive's nearest point, signed for faces [m]
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit, from the wall towards the centre
};

class DemWalls {
 public:
  /// The six faces of the box [lower, upper], normals inwards.
  static DemWalls box(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper);

  void addFace(const WallFace& face) { faces_.push_back(face); }
  void addEdge(const WallEdge& edge) { edges_.push_back(edge); }

  /// Number of primitives: faces first, then edges.
  std::size_t size() const { return faces_.size() + edges_.size(); }
  const std::vector<WallFace>& faces() const { return faces_; }
  const std::vector<WallEdge>& edges() const { return edges_; }

  /// Contact of a centre c with primitive k when its distance is below `reach` (the radius).
  bool contact(std::size_t k, const Eigen::Vector3d& c, double reach, WallContact& out) const;

  /// Unsigned distance from c to primitive k's point set (bounded face or segment) [m]: a cheap
  /// over-estimate of which primitives a particle may touch before the next list rebuild.
  double distanceTo(std::size_t k, const Eigen::Vector3d& c) const;

  /// Smallest distanceTo over all primitives [m] (insertion clearance).
  double clearance(const Eigen::Vector3d& c) const;

 private:
  std::vector<WallFace> faces_;
  std::vector<WallEdge> edges_;
};

}  // namespace rcfd
