#include "cfddem/ApparatusWalls.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/Errors.hpp"

namespace rcfd {

using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

/// Chains edges into closed loops of points by matching end points.
std::vector<std::vector<Vector2d>> loopsOf(const std::vector<SectionEdge>& edges) {
  const double tol = 1e-9;
  std::vector<bool> used(edges.size(), false);
  std::vector<std::vector<Vector2d>> loops;
  for (std::size_t s = 0; s < edges.size(); ++s) {
    if (used[s]) continue;
    used[s] = true;
    std::vector<Vector2d> loop{edges[s].a};
    Vector2d end = edges[s].b;
    for (;;) {
      if ((end - loop.front()).norm() < tol) break;
      loop.push_back(end);
      bool found = false;
      for (std::size_t k = 0; k < edges.size() && !found; ++k) {
        if (used[k]) continue;
        if ((edges[k].a - end).norm() < tol) { end = edges[k].b; found = true; }
        else if ((edges[k].b - end).norm() < tol) { end = edges[k].a; found = true; }
        if (found) used[k] = true;
      }
      if (!found) throw RunError("DEM walls: the apparatus cross-section has an open loop");
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

double signedArea(const std::vector<Vector2d>& loop) {
  double a = 0.0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const Vector2d& p = loop[i];
    const Vector2d& q = loop[(i + 1) % loop.size()];
    a += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * a;
}

}  // namespace

DemWalls wallsFromSection(const std::vector<SectionEdge>& edges, double depth) {
  DemWalls walls;
  auto loops = loopsOf(edges);
  if (loops.empty()) return walls;
  std::size_t outer = 0;
  for (std::size_t l = 1; l < loops.size(); ++l)
    if (std::abs(signedArea(loops[l])) > std::abs(signedArea(loops[outer]))) outer = l;

  for (std::size_t l = 0; l < loops.size(); ++l) {
    auto& loop = loops[l];
    // Orient every loop so that the open region lies on its left: the outer loop counter-clockwise,
    // holes clockwise. Then the normal into the open region is the left normal (-dy, dx).
    const bool ccw = signedArea(loop) > 0.0;
    if ((l == outer) != ccw) std::reverse(loop.begin(), loop.end());
    const std::size_t n = loop.size();
    double min_len = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) min_len = std::min(min_len, (loop[(i + 1) % n] - loop[i]).norm());
    for (std::size_t i = 0; i < n; ++i) {
      const Vector2d a = loop[i], b = loop[(i + 1) % n];
      const Vector2d d = (b - a).normalized();
      WallFace f;
      f.origin = Vector3d(a.x(), a.y(), 0.0);
      f.u = Vector3d(d.x(), d.y(), 0.0);
      f.normal = Vector3d(-d.y(), d.x(), 0.0);
      f.w = Vector3d::UnitZ();
      f.a_min = 0.0;
      f.a_max = (b - a).norm();
      f.b_min = 0.0;
      f.b_max = depth;
      // A plate is thin: a centre beyond its mid-plane belongs to the opposite face.
      if (l != outer) f.min_distance = -0.5 * min_len;
      walls.addFace(f);
    }
    // Convex wall corners: the next edge turns away from the open region (d2 . n1 < 0).
    for (std::size_t i = 0; i < n; ++i) {
      const Vector2d v = loop[(i + 1) % n];
      const Vector2d d1 = (v - loop[i]).normalized();
      const Vector2d d2 = (loop[(i + 2) % n] - v).normalized();
      const Vector2d n1(-d1.y(), d1.x());
      if (d2.dot(n1) >= -1e-12) continue;
      WallEdge e;
      e.origin = Vector3d(v.x(), v.y(), 0.0);
      e.dir = Vector3d::UnitZ();
      e.length = depth;
      e.f1 = Vector3d(-d1.x(), -d1.y(), 0.0);
      e.f2 = Vector3d(d2.x(), d2.y(), 0.0);
      walls.addEdge(e);
    }
  }
  for (int side = 0; side < 2; ++side) {
    WallFace f;
    f.origin = Vector3d(0.0, 0.0, side == 0 ? 0.0 : depth);
    f.normal = Vector3d(0.0, 0.0, side == 0 ? 1.0 : -1.0);
    f.u = Vector3d::UnitX();
    f.w = Vector3d::UnitY();
    walls.addFace(f);
  }
  return walls;
}

DemWalls wallsFromApparatus(const Apparatus& apparatus) {
  const ApparatusSpec& s = apparatus.spec();
  const double depth = s.type == ApparatusSpec::Type::Box ? s.size.z() : s.depth;
  return wallsFromSection(apparatus.sectionEdges(), depth);
}

}  // namespace rcfd
