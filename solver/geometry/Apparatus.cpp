#include "geometry/Apparatus.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "core/Errors.hpp"

namespace rcfd {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

/// Tolerance band of firstIntersection() relative to the largest extent of the apparatus: far below any
/// physical length (particles are millimetres) and far above double round-off (~1e-16 relative).
constexpr double kRelativeTolerance = 1e-9;
/// Round-off of a coordinate difference relative to the apparatus size (a few ulp of the coordinates).
constexpr double kRelativeNoise = 1e-15;
/// Plates must keep at least this many tolerance bands of clearance from the outer walls, so the open
/// region is one connected set whose distance function is the minimum of the parts' distances.
constexpr double kClearanceBands = 100.0;

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

double cross2(const Vector2d& a, const Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

/// Signed distance of p to an axis-aligned rectangle, > 0 outside; q nearest boundary point, n the unit
/// normal pointing out of the rectangle at q.
double boxDistance(const Vector2d& p, const Vector2d& lo, const Vector2d& hi, Vector2d& q, Vector2d& n) {
  const Vector2d c = 0.5 * (lo + hi), h = 0.5 * (hi - lo);
  const Vector2d rel = p - c;
  const Vector2d dv = rel.cwiseAbs() - h;
  if (dv.x() > 0.0 || dv.y() > 0.0) {
    q = p.cwiseMax(lo).cwiseMin(hi);
    const Vector2d out = p - q;
    const double d = out.norm();
    if (d > 0.0) {
      n = out / d;
      return d;
    }
    // On the boundary up to round-off of dv: treat as on the face below.
  }
  // Inside or on the boundary: nearest face is the one with the largest (least negative) excess.
  const int axis = dv.x() >= dv.y() ? 0 : 1;
  n = Vector2d::Zero();
  n[axis] = rel[axis] >= 0.0 ? 1.0 : -1.0;
  q = p;
  q[axis] = rel[axis] >= 0.0 ? hi[axis] : lo[axis];
  return dv[axis];
}

}  // namespace

Apparatus::Apparatus(const ApparatusSpec& spec) : spec_(spec) {
  std::vector<Violation> bad;
  auto require = [&](bool ok, const std::string& pointer, const std::string& message) {
    if (!ok) bad.push_back({pointer, message});
  };
  auto positive = [&](double v, const std::string& pointer) {
    require(std::isfinite(v) && v > 0.0, pointer, fmt(v) + " must be a finite number > 0 [m]");
  };

  double halfWidth = 0.0, top = 0.0;
  BoundaryKind topKind = BoundaryKind::Outlet;
  if (spec.type == ApparatusSpec::Type::PrismaticSpoutedBed) {
    positive(spec.width, "/apparatus/width");
    positive(spec.depth, "/apparatus/depth");
    positive(spec.height, "/apparatus/height");
    positive(spec.inlet_width, "/apparatus/inlet_width");
    require(std::isfinite(spec.prism_angle_deg) && spec.prism_angle_deg > 0.0 && spec.prism_angle_deg < 90.0,
            "/apparatus/prism_angle_deg", fmt(spec.prism_angle_deg) + " must lie in (0, 90) degrees");
    if (!bad.empty()) throw InputError("apparatus", bad);
    require(spec.inlet_width < spec.width, "/apparatus/inlet_width",
            fmt(spec.inlet_width) + " m must be smaller than the chamber width " + fmt(spec.width) + " m");
    if (!bad.empty()) throw InputError("apparatus", bad);
    const double tanA = std::tan(spec.prism_angle_deg * std::numbers::pi / 180.0);
    yV_ = 0.5 * (spec.width - spec.inlet_width) * tanA;
    require(spec.height > yV_, "/apparatus/height",
            fmt(spec.height) + " m must exceed the height of the V-bottom, (width - inlet_width)/2 * "
            "tan(prism_angle) = " + fmt(yV_) + " m");
    if (!bad.empty()) throw InputError("apparatus", bad);
    halfWidth = 0.5 * spec.width;
    top = spec.height;
    depth_ = spec.depth;
    const double wi = 0.5 * spec.inlet_width;
    outline_ = {{-wi, 0.0}, {wi, 0.0}, {halfWidth, yV_}, {halfWidth, top}, {-halfWidth, top}, {-halfWidth, yV_}};
    const BoundaryKind kinds[] = {BoundaryKind::Inlet, BoundaryKind::Wall, BoundaryKind::Wall,
                                  BoundaryKind::Outlet, BoundaryKind::Wall, BoundaryKind::Wall};
    for (std::size_t i = 0; i < outline_.size(); ++i)
      edges_.push_back({outline_[i], outline_[(i + 1) % outline_.size()], kinds[i]});
  } else {
    for (int d = 0; d < 3; ++d) positive(spec.size[d], "/apparatus/size/" + std::to_string(d));
    if (!bad.empty()) throw InputError("apparatus", bad);
    halfWidth = 0.5 * spec.size.x();
    top = spec.size.y();
    depth_ = spec.size.z();
    yV_ = 0.0;
    topKind = spec.box_outlet_top ? BoundaryKind::Outlet : BoundaryKind::Wall;
    outline_ = {{-halfWidth, 0.0}, {halfWidth, 0.0}, {halfWidth, top}, {-halfWidth, top}};
    const BoundaryKind kinds[] = {BoundaryKind::Wall, BoundaryKind::Wall, topKind, BoundaryKind::Wall};
    for (std::size_t i = 0; i < outline_.size(); ++i)
      edges_.push_back({outline_[i], outline_[(i + 1) % outline_.size()], kinds[i]});
  }
  lo2_ = Vector2d(-halfWidth, 0.0);
  hi2_ = Vector2d(halfWidth, top);
  tol_ = kRelativeTolerance * std::max({2.0 * halfWidth, top, depth_});
  noise_ = kRelativeNoise * std::max({2.0 * halfWidth, top, depth_});

  for (const auto& e : edges_) {
    const Vector2d dir = (e.b - e.a).normalized();
    const Vector2d n(-dir.y(), dir.x());  // left of a counter-clockwise edge = inside
    planes_.push_back({n, n.dot(e.a), e.kind});
  }
  // The outline must be convex: firstIntersection() and the distance rely on it.
  for (std::size_t i = 0; i < outline_.size(); ++i) {
    const Vector2d& a = outline_[i];
    const Vector2d& b = outline_[(i + 1) % outline_.size()];
    const Vector2d& c = outline_[(i + 2) % outline_.size()];
    if (cross2(b - a, c - b) <= 0.0) throw std::logic_error("Apparatus: outline is not strictly convex");
  }

  if (spec.draft_plates) {
    const DraftPlatesSpec& dp = *spec.draft_plates;
    positive(dp.height, "/apparatus/draft_plates/height");
    positive(dp.gap, "/apparatus/draft_plates/gap");
    positive(dp.thickness, "/apparatus/draft_plates/thickness");
    require(std::isfinite(dp.elevation) && dp.elevation >= 0.0, "/apparatus/draft_plates/elevation",
            fmt(dp.elevation) + " must be a finite number >= 0 [m]");
    if (!bad.empty()) throw InputError("apparatus", bad);
    const double clearance = kClearanceBands * tol_;
    const double inner = 0.5 * dp.gap, outer = inner + dp.thickness;
    require(outer < halfWidth - clearance, "/apparatus/draft_plates/gap",
            "the plates' outer faces at x = +-(gap/2 + thickness) = +-" + fmt(outer) +
                " m must lie inside the side walls at x = +-" + fmt(halfWidth) + " m");
    require(dp.elevation + dp.height < top - clearance, "/apparatus/draft_plates/height",
            "the plates' upper edge at y = elevation + height = " + fmt(dp.elevation + dp.height) +
                " m must lie below the top of the chamber at y = " + fmt(top) + " m");
    if (bad.empty()) {
      // The floor rises outwards, so the plate's lower outer corner is the one that could cut into it.
      const double floor = floorHeight(outer);
      require(dp.elevation > floor + clearance, "/apparatus/draft_plates/elevation",
              fmt(dp.elevation) + " m puts the plates' lower edges into the floor: below the plates' "
              "outer faces (x = +-" + fmt(outer) + " m) the V-bottom reaches y = " + fmt(floor) +
              " m; the elevation must exceed that");
    }
    if (!bad.empty()) throw InputError("apparatus", bad);
    const double y0 = dp.elevation, y1 = dp.elevation + dp.height;
    plates_.push_back({Vector2d(-outer, y0), Vector2d(-inner, y1)});
    plates_.push_back({Vector2d(inner, y0), Vector2d(outer, y1)});
    platesLo_ = Vector2d(-outer, y0);
    platesHi_ = Vector2d(outer, y1);
    for (const auto& pb : plates_) {
      // Clockwise, so the open region lies on the left of every edge as for the outline.
      std::vector<Vector2d> hole{{pb.lo.x(), pb.lo.y()}, {pb.lo.x(), pb.hi.y()},
                                 {pb.hi.x(), pb.hi.y()}, {pb.hi.x(), pb.lo.y()}};
      for (std::size_t i = 0; i < hole.size(); ++i)
        edges_.push_back({hole[i], hole[(i + 1) % hole.size()], BoundaryKind::Plate});
      holes_.push_back(std::move(hole));
    }
  }

  // Analytic area: the rectangle minus the two triangles under the V walls, minus the plates.
  if (spec.type == ApparatusSpec::Type::PrismaticSpoutedBed) {
    sectionArea_ = spec.width * spec.height - 0.5 * (spec.width - spec.inlet_width) * yV_;
  } else {
    sectionArea_ = spec.size.x() * spec.size.y();
  }
  for (const auto& pb : plates_) sectionArea_ -= (pb.hi - pb.lo).prod();
}

Vector3d Apparatus::lowerCorner() const { return Vector3d(lo2_.x(), lo2_.y(), 0.0); }
Vector3d Apparatus::upperCorner() const { return Vector3d(hi2_.x(), hi2_.y(), depth_); }
double Apparatus::depth() const { return depth_; }
double Apparatus::sectionArea() const { return sectionArea_; }
double Apparatus::openVolume() const { return sectionArea_ * depth_; }

double Apparatus::floorHeight(double x) const {
  if (spec_.type == ApparatusSpec::Type::Box) return 0.0;
  const double tanA = std::tan(spec_.prism_angle_deg * std::numbers::pi / 180.0);
  return std::clamp((std::abs(x) - 0.5 * spec_.inlet_width) * tanA, 0.0, yV_);
}

bool Apparatus::contains(const Vector3d& p) const {
  if (!(p.z() >= 0.0 && p.z() <= depth_)) return false;
  const Vector2d p2 = p.head<2>();
  for (const auto& h : planes_)
    if (h.n.dot(p2) - h.c < 0.0) return false;
  for (const auto& pb : plates_)
    if (p2.x() > pb.lo.x() && p2.x() < pb.hi.x() && p2.y() > pb.lo.y() && p2.y() < pb.hi.y()) return false;
  return true;
}

double Apparatus::section2d(const Vector2d& p, Vector2d& q, Vector2d& n, BoundaryKind& kind) const {
  // Outer convex polygon: inside, the distance is the smallest half-plane distance (exact for a convex
  // polygon); outside, the distance to the nearest edge segment.
  double hmin = std::numeric_limits<double>::infinity();
  std::size_t imin = 0;
  for (std::size_t i = 0; i < planes_.size(); ++i) {
    const double h = planes_[i].n.dot(p) - planes_[i].c;
    if (h < hmin) {
      hmin = h;
      imin = i;
    }
  }
  double d;
  if (hmin >= 0.0) {
    d = hmin;
    n = planes_[imin].n;
    q = p - hmin * n;
    kind = planes_[imin].kind;
  } else {
    double best = std::numeric_limits<double>::infinity();
    std::size_t ibest = 0;
    Vector2d qbest = p;
    const std::size_t m = outline_.size();
    for (std::size_t i = 0; i < m; ++i) {
      const Vector2d& a = outline_[i];
      const Vector2d e = outline_[(i + 1) % m] - a;
      const double t = std::clamp((p - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
      const Vector2d qi = a + t * e;
      const double d2 = (p - qi).squaredNorm();
      if (d2 < best) {
        best = d2;
        ibest = i;
        qbest = qi;
      }
    }
    d = -std::sqrt(best);
    q = qbest;
    kind = planes_[ibest].kind;
    n = d < 0.0 ? Vector2d((q - p) / -d) : planes_[ibest].n;
  }
  // Plates lie strictly inside the outline, so the open region's distance is the minimum of the parts'.
  for (const auto& pb : plates_) {
    Vector2d qp, np;
    const double dp = boxDistance(p, pb.lo, pb.hi, qp, np);
    if (dp < d) {
      d = dp;
      q = qp;
      n = np;
      kind = BoundaryKind::Plate;
    }
  }
  return d;
}

NearestBoundary Apparatus::nearestBoundary(const Vector3d& p) const {
  Vector2d q2, n2;
  BoundaryKind kind2 = BoundaryKind::Wall;
  const double d2 = section2d(p.head<2>(), q2, n2, kind2);
  const bool lowFace = p.z() < 0.5 * depth_;
  const double dz = lowFace ? p.z() : depth_ - p.z();
  const double qz = lowFace ? 0.0 : depth_;
  const Vector3d nz(0.0, 0.0, lowFace ? 1.0 : -1.0);

  NearestBoundary r;
  // Exact distance of an extruded region: combine the 2D and the slab distances (inside: the smaller;
  // outside in both: the hypotenuse; otherwise the one that is outside).
  if ((d2 >= 0.0 && dz >= 0.0 && d2 <= dz) || (d2 < 0.0 && dz >= 0.0)) {
    r.distance = d2;
    r.normal = Vector3d(n2.x(), n2.y(), 0.0);
    r.point = Vector3d(q2.x(), q2.y(), p.z());
    r.kind = kind2;
  } else if (d2 >= 0.0) {
    r.distance = dz;
    r.normal = nz;
    r.point = Vector3d(p.x(), p.y(), qz);
    r.kind = BoundaryKind::Wall;
  } else {
    r.distance = -std::hypot(d2, dz);
    r.point = Vector3d(q2.x(), q2.y(), qz);
    r.normal = (r.point - p).normalized();
    r.kind = kind2;
  }
  return r;
}

double Apparatus::signedDistance(const Vector3d& p) const {
  Vector2d q2, n2;
  BoundaryKind kind2;
  const double d2 = section2d(p.head<2>(), q2, n2, kind2);
  const double dz = std::min(p.z(), depth_ - p.z());
  if (d2 >= 0.0 && dz >= 0.0) return std::min(d2, dz);
  if (d2 < 0.0 && dz < 0.0) return -std::hypot(d2, dz);
  return std::min(d2, dz);
}

std::vector<Apparatus::HalfSpace> Apparatus::convexHalfSpaces() const {
  std::vector<HalfSpace> out;
  for (const auto& h : planes_) out.push_back({Vector3d(h.n.x(), h.n.y(), 0.0), h.c});
  out.push_back({Vector3d(0.0, 0.0, 1.0), 0.0});
  out.push_back({Vector3d(0.0, 0.0, -1.0), -depth_});
  return out;
}

std::optional<BoundaryHit> Apparatus::firstIntersection(const Vector3d& a, const Vector3d& b) const {
  const Vector3d d = b - a;
  if (d.x() == 0.0 && d.y() == 0.0 && d.z() == 0.0) return std::nullopt;

  // Each wall is a constraint g(p) >= 0 (g = distance in front of the wall). A hit is the first t where
  // g(a + t d) drops to the tolerance band; a start inside the band moving outwards hits at t = 0.
  double tBest = std::numeric_limits<double>::infinity();
  Vector3d nBest = Vector3d::Zero();
  BoundaryKind kBest = BoundaryKind::Wall;
  auto planeConstraint = [&](double ga, double gb, const Vector3d& n, BoundaryKind kind) {
    double t;
    if (ga >= tol_) {
      if (gb >= tol_) return;  // both ends clear of this wall
      t = (ga - tol_) / (ga - gb);
    } else {
      // Starting in the band: only a genuine outward motion is a hit. Motion along the wall shows
      // round-off of either sign in ga - gb; calling that a hit would bounce for ever (the mirror image
      // of a parallel motion is the same motion), and ignoring it lets b be at most noise_ outside.
      if (ga - gb <= noise_) return;
      t = 0.0;
    }
    if (t < tBest) {
      tBest = t;
      nBest = n;
      kBest = kind;
    }
  };

  for (const auto& h : planes_) {
    const double ga = h.n.x() * a.x() + h.n.y() * a.y() - h.c;
    const double gb = h.n.x() * b.x() + h.n.y() * b.y() - h.c;
    planeConstraint(ga, gb, Vector3d(h.n.x(), h.n.y(), 0.0), h.kind);
  }
  planeConstraint(a.z(), b.z(), Vector3d(0.0, 0.0, 1.0), BoundaryKind::Wall);
  planeConstraint(depth_ - a.z(), depth_ - b.z(), Vector3d(0.0, 0.0, -1.0), BoundaryKind::Wall);

  if (!plates_.empty()) {
    // Fast rejection: the segment's x-y bounding box misses both (inflated) plates.
    const double sxLo = std::min(a.x(), b.x()), sxHi = std::max(a.x(), b.x());
    const double syLo = std::min(a.y(), b.y()), syHi = std::max(a.y(), b.y());
    const bool near = sxHi >= platesLo_.x() - tol_ && sxLo <= platesHi_.x() + tol_ &&
                      syHi >= platesLo_.y() - tol_ && syLo <= platesHi_.y() + tol_;
    if (near) {
      for (const auto& pb : plates_) {
        // Liang-Barsky entry into the plate inflated by the tolerance band.
        const Vector2d lo = pb.lo.array() - tol_, hi = pb.hi.array() + tol_;
        double tEnter = -std::numeric_limits<double>::infinity();
        double tExit = std::numeric_limits<double>::infinity();
        int enterAxis = -1;
        bool miss = false;
        for (int ax = 0; ax < 2 && !miss; ++ax) {
          if (d[ax] == 0.0) {
            if (a[ax] < lo[ax] || a[ax] > hi[ax]) miss = true;
            continue;
          }
          double t0 = (lo[ax] - a[ax]) / d[ax], t1 = (hi[ax] - a[ax]) / d[ax];
          if (t0 > t1) std::swap(t0, t1);
          if (t0 > tEnter) {
            tEnter = t0;
            enterAxis = ax;
          }
          tExit = std::min(tExit, t1);
        }
        if (miss || tEnter > tExit || tExit < 0.0 || tEnter > 1.0) continue;
        Vector3d n = Vector3d::Zero();
        double t;
        if (tEnter >= 0.0) {
          t = tEnter;
          n[enterAxis] = d[enterAxis] > 0.0 ? -1.0 : 1.0;  // out of the plate, against the motion
        } else {
          // a lies in the band (or the plate): hit now only if moving into the face a is in front of.
          const double s[4] = {pb.lo.x() - a.x(), a.x() - pb.hi.x(), pb.lo.y() - a.y(), a.y() - pb.hi.y()};
          const int f = int(std::max_element(s, s + 4) - s);
          n[f / 2] = (f % 2 == 0) ? -1.0 : 1.0;
          if (n.x() * d.x() + n.y() * d.y() >= 0.0) continue;
          t = 0.0;
        }
        if (t < tBest) {
          tBest = t;
          nBest = n;
          kBest = BoundaryKind::Plate;
        }
      }
    }
  }

  if (!(tBest <= 1.0)) return std::nullopt;
  BoundaryHit hit;
  hit.t = tBest;
  hit.point = tBest == 0.0 ? a : Vector3d(a + tBest * d);
  hit.normal = nBest;
  hit.kind = kBest;
  return hit;
}

ReflectedMove moveWithMirrorReflection(const Apparatus& apparatus, const Vector3d& a, const Vector3d& b,
                                       int maxBounces) {
  ReflectedMove r;
  Vector3d from = a, to = b;
  while (const auto hit = apparatus.firstIntersection(from, to)) {
    from = hit->point;
    if (r.bounces == maxBounces) {
      r.capped = true;
      r.end = from;
      return r;
    }
    ++r.bounces;
    const Vector3d rest = to - hit->point;
    to = from + rest - 2.0 * rest.dot(hit->normal) * hit->normal;
  }
  r.end = to;
  return r;
}

CartesianGrid makeGrid(const Apparatus& apparatus, const GridSpec& spec) {
  std::vector<Violation> bad;
  for (int dim = 0; dim < 3; ++dim) {
    const double c = spec.cell_size[dim];
    if (!(std::isfinite(c) && c > 0.0))
      bad.push_back({"/grid/cell_size", "component " + std::to_string(dim) + " = " + fmt(c) +
                                            " must be a finite number > 0 [m]"});
  }
  if (!bad.empty()) throw InputError("grid", bad);
  CartesianGrid g;
  g.origin = apparatus.lowerCorner();
  const Vector3d extent = apparatus.upperCorner() - apparatus.lowerCorner();
  for (int dim = 0; dim < 3; ++dim) {
    const double cells = std::max(1.0, std::round(extent[dim] / spec.cell_size[dim]));
    if (cells > 1e5)
      throw InputError("grid", "/grid/cell_size",
                       fmt(spec.cell_size[dim]) + " m gives " + fmt(cells) +
                           " cells along one axis; at most 100000 are allowed");
    g.shape[dim] = int(cells);
    g.spacing[dim] = extent[dim] / cells;
  }
  return g;
}

}  // namespace rcfd
