#pragma once
// The ProCell cross-section (ApparatusSpec defaults: V-bottom of 60 deg above a 20 mm inlet slot,
// draft plates 45 mm apart), built here so the DEM wall tests do not depend on Apparatus.cpp; and an
// exact inside test for it.
#include <cmath>
#include <vector>

#include "geometry/Apparatus.hpp"

namespace rcfd::demtest {

struct ProCell {
  ApparatusSpec spec;
  bool plates = true;
  DraftPlatesSpec plate;  ///< elevation 0.03 m: plates clear of the V, all four edges exposed
  ProCell() { plate.elevation = 0.03; }
  double wi() const { return 0.5 * spec.inlet_width; }
  double yv() const {
    return (0.5 * spec.width - wi()) * std::tan(spec.prism_angle_deg * M_PI / 180.0);
  }
  std::vector<Eigen::Vector2d> outline() const {
    const double w = 0.5 * spec.width;
    return {{-wi(), 0.0}, {wi(), 0.0}, {w, yv()}, {w, spec.height}, {-w, spec.height}, {-w, yv()}};
  }
  /// Plate rectangles as (x0, y0, x1, y1).
  std::vector<Eigen::Vector4d> plateRects() const {
    if (!plates) return {};
    const DraftPlatesSpec& p = plate;
    const double x0 = 0.5 * p.gap, x1 = x0 + p.thickness, y0 = p.elevation, y1 = y0 + p.height;
    return {{x0, y0, x1, y1}, {-x1, y0, -x0, y1}};
  }
  std::vector<SectionEdge> edges() const {
    std::vector<SectionEdge> e;
    const auto o = outline();
    for (std::size_t i = 0; i < o.size(); ++i)
      e.push_back({o[i], o[(i + 1) % o.size()], i == 0 ? BoundaryKind::Inlet : BoundaryKind::Wall});
    for (const auto& r : plateRects()) {
      const Eigen::Vector2d a(r[0], r[1]), b(r[2], r[1]), c(r[2], r[3]), d(r[0], r[3]);
      e.push_back({a, b, BoundaryKind::Plate});
      e.push_back({b, c, BoundaryKind::Plate});
      e.push_back({c, d, BoundaryKind::Plate});
      e.push_back({d, a, BoundaryKind::Plate});
    }
    return e;
  }
  /// Signed clearance of a point: distance to the nearest wall, negative outside the open region.
  double clearance(const Eigen::Vector3d& p) const {
    const auto o = outline();
    double d = std::min(p.z(), spec.depth - p.z());
    for (std::size_t i = 0; i < o.size(); ++i) {  // convex outline: min of the signed line distances
      const Eigen::Vector2d a = o[i], b = o[(i + 1) % o.size()];
      const Eigen::Vector2d t = (b - a).normalized();
      d = std::min(d, (Eigen::Vector2d(p.x(), p.y()) - a).dot(Eigen::Vector2d(-t.y(), t.x())));
    }
    for (const auto& r : plateRects()) {
      const double dx = std::max(r[0] - p.x(), p.x() - r[2]), dy = std::max(r[1] - p.y(), p.y() - r[3]);
      const double outside = (dx > 0 || dy > 0) ? std::hypot(std::max(dx, 0.0), std::max(dy, 0.0))
                                                : std::max(dx, dy);
      d = std::min(d, outside);
    }
    return d;
  }
};

}  // namespace rcfd::demtest
