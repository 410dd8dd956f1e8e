#include "geometry/SprayZone.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>
#include <numbers>
#include <sstream>
#include <utility>

#include "core/Errors.hpp"
#include "geometry/Apparatus.hpp"

namespace rcfd {
namespace {
std::string fmt(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}
/// Integral of the half-chord h(t) = sqrt(r^2 - t^2) of a disk of radius r from -r to t (|t| <= r).
double halfChordIntegral(double t, double r) {
  const double h = std::sqrt(std::max(0.0, r * r - t * t));
  return 0.5 * (t * h + r * r * std::asin(std::clamp(t / r, -1.0, 1.0))) + 0.25 * std::numbers::pi * r * r;
}

/// Area of the disk of radius r centred at the origin with X <= x and Z <= z.
double quadrantArea(double x, double z, double r) {
  if (z <= -r || x <= -r) return 0.0;
  const double X = std::min(x, r);
  auto H = [r](double t) { return halfChordIntegral(t, r); };
  if (z >= r) return 2.0 * H(X);
  // Where |t| > c the chord lies entirely below z (z > 0) or above it (z < 0); for |t| < c it is cut.
  const double c = std::sqrt(r * r - z * z);
  double area = 0.0;
  const double a1 = std::min(X, -c);  // [-r, -c]
  if (z > 0.0) area += 2.0 * (H(a1) - H(-r));
  if (X > -c) {
    const double b = std::min(X, c);  // [-c, c]: chord from -h to z
    area += z * (b + c) + H(b) - H(-c);
  }
  if (X > c && z > 0.0) area += 2.0 * (H(X) - H(c));  // [c, r]
  return area;
}

/// Area of the disk (centre (cx, cz), radius r) inside the rectangle [x0, x1] x [z0, z1].
double diskRectangleArea(double cx, double cz, double r, double x0, double x1, double z0, double z1) {
  if (r <= 0.0 || x1 <= x0 || z1 <= z0) return 0.0;
  x0 -= cx, x1 -= cx, z0 -= cz, z1 -= cz;
  return quadrantArea(x1, z1, r) - quadrantArea(x0, z1, r) - quadrantArea(x1, z0, r) + quadrantArea(x0, z0, r);
}

}  // namespace

SprayZone::SprayZone(const SprayZoneSpec& spec) : spec_(spec) {
  std::vector<Violation> bad;
  const std::string base = "/spray/spray_zone/";
  if (!(std::isfinite(spec.half_angle_deg) && spec.half_angle_deg > 0.0 && spec.half_angle_deg < 90.0))
    bad.push_back({base + "half_angle_deg", fmt(spec.half_angle_deg) + " must lie in (0, 90) degrees"});
  if (!spec.apex.allFinite()) bad.push_back({base + "apex", "must be three finite numbers [m]"});
  if (!(std::isfinite(spec.y_min) && std::isfinite(spec.y_max) && spec.y_min < spec.y_max))
    bad.push_back({base + "y_max", fmt(spec.y_max) + " m must exceed y_min = " + fmt(spec.y_min) + " m"});
  if (std::isfinite(spec.y_min) && spec.y_min < spec.apex.y())
    bad.push_back({base + "y_min", fmt(spec.y_min) + " m lies below the cone's apex at y = " +
                                       fmt(spec.apex.y()) + " m; it must be >= the apex height"});
  if (!bad.empty()) throw InputError("spray zone", bad);
  tanHalfAngle_ = std::tan(spec.half_angle_deg * std::numbers::pi / 180.0);
}

SprayZone::SprayZone(const SprayZoneSpec& spec, const Apparatus& apparatus) : SprayZone(spec) {
  if (!spec.line_of_sight) return;
  for (const auto& hole : apparatus.holes()) {
    Shadow s{hole[0].x(), hole[0].x(), hole[0].y(), hole[0].y()};
    for (const auto& p : hole) {
      s.x0 = std::min(s.x0, p.x()), s.x1 = std::max(s.x1, p.x());
      s.y0 = std::min(s.y0, p.y()), s.y1 = std::max(s.y1, p.y());
    }
    // A plate wholly below the apex or above the zone shadows nothing in it.
    if (s.y1 > spec.apex.y() && s.y0 < spec.y_max) shadows_.push_back(s);
  }
}

// The segment from the apex a to a point p at height y > a.y passes the heights y' in [max(y0, a.y),
// min(y1, y)] of the plate at x' = a.x + (p.x - a.x) h / H, h = y' - a.y, H = y - a.y. It meets the plate
// when those x' reach [x0, x1]; for a given point that is a test on the two ends, and over the points
// of a height it is one interval (each h maps [x0, x1] to dx in [c0 H / h, c1 H / h]).
bool SprayZone::shadowed(double x, double y) const {
  const double H = y - spec_.apex.y();
  if (!(H > 0.0)) return false;
  const double dx = x - spec_.apex.x();
  for (const Shadow& s : shadows_) {
    const double h0 = std::max(s.y0 - spec_.apex.y(), 0.0), h1 = std::min(s.y1, y) - spec_.apex.y();
    if (!(h1 >= h0)) continue;
    const double c0 = (s.x0 - spec_.apex.x()) * H, c1 = (s.x1 - spec_.apex.x()) * H;
    const double lo = std::min(dx * h0, dx * h1), hi = std::max(dx * h0, dx * h1);
    if (lo <= c1 && hi >= c0) return true;
  }
  return false;
}

std::pair<double, double> SprayZone::shadowAt(const Shadow& s, double y) const {
  const double inf = std::numeric_limits<double>::infinity();
  const double H = y - spec_.apex.y();
  const double h0 = std::max(s.y0 - spec_.apex.y(), 0.0), h1 = std::min(s.y1, y) - spec_.apex.y();
  if (!(H > 0.0) || !(h1 > 0.0) || h1 < h0) return {inf, -inf};
  const double c0 = (s.x0 - spec_.apex.x()) * H, c1 = (s.x1 - spec_.apex.x()) * H;
  // The ends of the union over h in [h0, h1] of [c0 / h, c1 / h]; h -> 0 sends a non-zero end to infinity.
  auto end = [&](double c, bool lower) {
    if (h0 > 0.0) return lower ? std::min(c / h0, c / h1) : std::max(c / h0, c / h1);
    if (c == 0.0) return 0.0;
    if (lower) return c > 0.0 ? c / h1 : -inf;
    return c < 0.0 ? c / h1 : inf;
  };
  return {spec_.apex.x() + end(c0, true), spec_.apex.x() + end(c1, false)};
}

double SprayZone::radiusAt(double y) const {
  return y <= spec_.apex.y() ? 0.0 : (y - spec_.apex.y()) * tanHalfAngle_;
}

double SprayZone::volume() const {
  const double h1 = spec_.y_max - spec_.apex.y(), h0 = spec_.y_min - spec_.apex.y();
  return std::numbers::pi * tanHalfAngle_ * tanHalfAngle_ / 3.0 * (h1 * h1 * h1 - h0 * h0 * h0);
}

double SprayZone::volumeInside(const Apparatus& apparatus, int slices) const {
  const auto& outline = apparatus.outline();
  const double depth = apparatus.depth();
  const double cx = spec_.apex.x(), cz = spec_.apex.z();
  // Open area of the zone's disk at height y: the outline's x-range at y (convex: one interval) times
  // [0, depth], minus the plates at that height.
  auto area = [&](double y) {
    double xl = -std::numeric_limits<double>::infinity(), xr = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < outline.size(); ++i) {
      const Eigen::Vector2d e = outline[(i + 1) % outline.size()] - outline[i];
      const Eigen::Vector2d n(-e.y(), e.x());  // inward for the counter-clockwise outline
      const double c = n.dot(outline[i]) - n.y() * y;  // n.x x >= c
      if (n.x() > 0.0) xl = std::max(xl, c / n.x());
      else if (n.x() < 0.0) xr = std::min(xr, c / n.x());
      else if (c > 0.0) return 0.0;
    }
    const double r = radiusAt(y);
    double a = diskRectangleArea(cx, cz, r, xl, xr, 0.0, depth);
    // The x-intervals left out at this height: the plates themselves and their shadows, merged so
    // that an overlap is subtracted once.
    std::vector<std::pair<double, double>> out;
    for (const auto& hole : apparatus.holes()) {
      double hx0 = hole[0].x(), hx1 = hole[0].x(), hy0 = hole[0].y(), hy1 = hole[0].y();
      for (const auto& p : hole) {
        hx0 = std::min(hx0, p.x()), hx1 = std::max(hx1, p.x());
        hy0 = std::min(hy0, p.y()), hy1 = std::max(hy1, p.y());
      }
      if (y > hy0 && y < hy1) out.emplace_back(hx0, hx1);
    }
    for (const Shadow& s : shadows_) out.push_back(shadowAt(s, y));
    std::sort(out.begin(), out.end());
    bool running = false;
    double runLo = 0.0, runHi = 0.0;
    auto subtract = [&] {
      const double lo = std::max(runLo, xl), hi = std::min(runHi, xr);
      if (running && hi > lo) a -= diskRectangleArea(cx, cz, r, lo, hi, 0.0, depth);
    };
    for (const auto& [lo, hi] : out) {
      if (!(hi > lo)) continue;
      if (!running || lo > runHi) {
        subtract();
        running = true, runLo = lo, runHi = hi;
      } else {
        runHi = std::max(runHi, hi);
      }
    }
    subtract();
    return std::max(0.0, a);
  };
  // Split at the heights where the open section changes shape (plate edges, outline corners), so
  // Simpson integrates smooth pieces.
  std::vector<double> cuts{spec_.y_min, spec_.y_max};
  for (const auto& p : outline) cuts.push_back(p.y());
  for (const auto& hole : apparatus.holes())
    for (const auto& p : hole) cuts.push_back(p.y());
  std::sort(cuts.begin(), cuts.end());
  double volume = 0.0;
  const int perPiece = std::max(2, slices / int(cuts.size()));
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double y0 = std::max(cuts[k], spec_.y_min), y1 = std::min(cuts[k + 1], spec_.y_max);
    if (y1 <= y0) continue;
    const int n = perPiece + perPiece % 2;  // even
    const double h = (y1 - y0) / n;
    double sum = area(y0) + area(y1);
    for (int i = 1; i < n; ++i) sum += (i % 2 ? 4.0 : 2.0) * area(y0 + i * h);
    volume += sum * h / 3.0;  // composite Simpson
  }
  return volume;
}

}  // namespace rcfd
