#include "cfddem/DemWalls.hpp"

#include <algorithm>
#include <cmath>

namespace rcfd {

using Eigen::Vector3d;

DemWalls DemWalls::box(const Vector3d& lo, const Vector3d& hi) {
  DemWalls walls;
  for (int axis = 0; axis < 3; ++axis) {
    const int ua = (axis + 1) % 3, wa = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      WallFace f;
      f.origin = side == 0 ? lo : hi;
      f.normal = Vector3d::Unit(axis) * (side == 0 ? 1.0 : -1.0);
      f.u = Vector3d::Unit(ua);
      f.w = Vector3d::Unit(wa);
      // Bounded to the box so that the three faces meeting at a corner each count only where the
      // centre projects onto them (all box corners are concave: both faces act, as they should).
      f.a_min = lo[ua] - f.origin[ua];
      f.a_max = hi[ua] - f.origin[ua];
      f.b_min = lo[wa] - f.origin[wa];
      f.b_max = hi[wa] - f.origin[wa];
      walls.addFace(f);
    }
  }
  return walls;
}

bool DemWalls::contact(std::size_t k, const Vector3d& c, double reach, WallContact& out) const {
  if (k < faces_.size()) {
    const WallFace& f = faces_[k];
    const Vector3d rel = c - f.origin;
    const double d = rel.dot(f.normal);
    if (d >= reach || d <= f.min_distance) return false;
    const double a = rel.dot(f.u), b = rel.dot(f.w);
    if (a < f.a_min || a > f.a_max || b < f.b_min || b > f.b_max) return false;
    out.distance = d;
    out.normal = f.normal;
    return true;
  }
  const WallEdge& e = edges_[k - faces_.size()];
  const Vector3d rel = c - e.origin;
  // Voronoi wedge of a convex edge: the centre projects outside both adjacent faces.
  if (rel.dot(e.f1) > 0.0 || rel.dot(e.f2) > 0.0) return false;
  const double s = std::clamp(rel.dot(e.dir), 0.0, e.length);
  const Vector3d dv = rel - s * e.dir;
  const double d2 = dv.squaredNorm();
  if (d2 >= reach * reach || d2 == 0.0) return false;
  out.distance = std::sqrt(d2);
  out.normal = dv / out.distance;
  return true;
}

double DemWalls::distanceTo(std::size_t k, const Vector3d& c) const {
  if (k < faces_.size()) {
    const WallFace& f = faces_[k];
    const Vector3d rel = c - f.origin;
    const double a = std::clamp(rel.dot(f.u), f.a_min, f.a_max);
    const double b = std::clamp(rel.dot(f.w), f.b_min, f.b_max);
    const double d = rel.dot(f.normal);
    const double da = rel.dot(f.u) - a, db = rel.dot(f.w) - b;
    return std::sqrt(d * d + da * da + db * db);
  }
  const WallEdge& e = edges_[k - faces_.size()];
  const Vector3d rel = c - e.origin;
  const double s = std::clamp(rel.dot(e.dir), 0.0, e.length);
  return (rel - s * e.dir).norm();
}

double DemWalls::clearance(const Vector3d& c) const {
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < size(); ++k) d = std::min(d, distanceTo(k, c));
  return d;
}

}  // namespace rcfd
