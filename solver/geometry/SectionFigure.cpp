#include "geometry/SectionFigure.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "core/AxisTicks.hpp"
#include "geometry/Apparatus.hpp"
#include "geometry/SprayZone.hpp"

namespace rcfd {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

// Colours shared by the drawing and its legend.
const std::string kWall = "#000000";
const std::string kInlet = "#1f77b4";
const std::string kOutlet = "#d62728";
const std::string kPlate = "#7f7f7f";
const std::string kNozzle = "#2ca02c";
const std::string kCone = "#9467bd";
const std::string kZone = "#ff7f0e";
const std::string kGrid = "#d9d9d9";
const std::string kOpen = "#eef4fa";

constexpr double kPlotHeightPx = 700.0;  ///< height of the drawing area
constexpr double kMarginPx = 55.0;
constexpr double kLegendWidthPx = 200.0;

std::string fmt(double v, int precision = 4) {
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}


/// Where a drawing goes: the part of the section inside [lo, hi] (scene coordinates), scaled by `zoom`
/// about `lo` and placed at `at` (user coordinates of the document). The main view is the identity.
struct View {
  Vector2d lo, hi;
  Vector2d at;
  double zoom = 1.0;
  Vector2d map(const Vector2d& p) const { return at + zoom * (p - lo); }
};

/// Liang-Barsky: clips the segment to the view's window; false if nothing is left.
bool clipSegment(const View& v, Vector2d& a, Vector2d& b) {
  double t0 = 0.0, t1 = 1.0;
  const Vector2d d = b - a;
  for (int ax = 0; ax < 2; ++ax) {
    if (d[ax] == 0.0) {
      if (a[ax] < v.lo[ax] || a[ax] > v.hi[ax]) return false;
      continue;
    }
    double s0 = (v.lo[ax] - a[ax]) / d[ax], s1 = (v.hi[ax] - a[ax]) / d[ax];
    if (s0 > s1) std::swap(s0, s1);
    t0 = std::max(t0, s0);
    t1 = std::min(t1, s1);
    if (t0 > t1) return false;
  }
  const Vector2d a0 = a;
  a = a0 + t0 * d;
  b = a0 + t1 * d;
  return true;
}

/// Sutherland-Hodgman against the view's window (the window is convex, so any polygon clips right).
std::vector<Vector2d> clipPolygon(const View& v, std::vector<Vector2d> poly) {
  for (int side = 0; side < 4 && !poly.empty(); ++side) {
    const int ax = side / 2;
    const double sign = side % 2 == 0 ? 1.0 : -1.0;
    const double value = side % 2 == 0 ? v.lo[ax] : v.hi[ax];
    std::vector<Vector2d> out;
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Vector2d& p = poly[i];
      const Vector2d& q = poly[(i + 1) % poly.size()];
      const double dp = sign * (p[ax] - value), dq = sign * (q[ax] - value);
      if (dp >= 0.0) out.push_back(p);
      if ((dp >= 0.0) != (dq >= 0.0)) out.push_back(p + dp / (dp - dq) * (q - p));
    }
    poly = std::move(out);
  }
  return poly;
}

/// Draws the section into `doc` through `view`.
class SectionPainter {
 public:
  SectionPainter(SvgDocument& doc, const View& view) : doc_(doc), v_(view) {}

  void line(Vector2d a, Vector2d b, const std::string& stroke, double widthPx, double opacity = 1.0,
            const std::string& dash = "") {
    if (!clipSegment(v_, a, b)) return;
    a = v_.map(a), b = v_.map(b);
    if (opacity < 1.0) {
      doc_.translucentLine(a.x(), a.y(), b.x(), b.y(), stroke, widthPx, opacity, dash);
    } else {
      doc_.line(a.x(), a.y(), b.x(), b.y(), stroke, widthPx, dash);
    }
  }
  void polygon(const std::vector<Vector2d>& pts, const std::string& fill, const std::string& stroke,
               double widthPx, double opacity = 1.0) {
    const auto clipped = clipPolygon(v_, pts);
    if (clipped.size() < 3) return;
    std::vector<std::array<double, 2>> out;
    for (const auto& p : clipped) {
      const Vector2d m = v_.map(p);
      out.push_back({m.x(), m.y()});
    }
    doc_.polygon(out, fill, stroke, widthPx, opacity);
  }
  void circle(const Vector2d& c, double radiusPx, const std::string& fill) {
    if ((c.array() < v_.lo.array()).any() || (c.array() > v_.hi.array()).any()) return;
    const Vector2d m = v_.map(c);
    doc_.circle(m.x(), m.y(), radiusPx, fill);
  }
  void text(const Vector2d& p, double dyPx, const std::string& t, const std::string& fill, double scale) {
    if ((p.array() < v_.lo.array()).any() || (p.array() > v_.hi.array()).any()) return;
    const Vector2d m = v_.map(p);
    doc_.text(m.x(), m.y() + dyPx / scale, t, 12, "middle", fill);
  }

 private:
  SvgDocument& doc_;
  View v_;
};

void paint(SectionPainter& pen, const Scene& scene, const Apparatus& app, const CartesianGrid& grid,
           const SprayZone& zone, double extent, double scale) {
  // Open region, lightly tinted, then the grid lines over it.
  pen.polygon(app.outline(), kOpen, "none", 0.0);
  const Vector3d gHi = grid.upperCorner();
  for (int i = 0; i <= grid.shape[0]; ++i) {
    const double x = grid.origin.x() + i * grid.spacing.x();
    pen.line({x, grid.origin.y()}, {x, gHi.y()}, kGrid, 0.5);
  }
  for (int j = 0; j <= grid.shape[1]; ++j) {
    const double y = grid.origin.y() + j * grid.spacing.y();
    pen.line({grid.origin.x(), y}, {gHi.x(), y}, kGrid, 0.5);
  }

  // Spray zone: its axial section, a trapezoid (exact in the plane z = apex.z).
  const SprayZoneSpec& zs = scene.spray.spray_zone;
  const double r0 = zone.radiusAt(zs.y_min), r1 = zone.radiusAt(zs.y_max);
  const double ax = zs.apex.x();
  pen.polygon({{ax - r0, zs.y_min}, {ax + r0, zs.y_min}, {ax + r1, zs.y_max}, {ax - r1, zs.y_max}}, kZone,
              kZone, 1.0, 0.3);

  // Spray cone: rays from the nozzle at +-half-angle until they meet a wall, a plate or the outlet.
  const Vector3d nozzle = scene.spray.nozzle_position;
  const double half = scene.spray.cone_half_angle_deg * std::numbers::pi / 180.0;
  for (double side : {-1.0, 0.0, 1.0}) {
    const Vector3d dir(side * std::sin(half), side == 0.0 ? 1.0 : std::cos(half), 0.0);
    const Vector3d far = nozzle + 2.0 * extent * dir;
    const auto hit = app.contains(nozzle) ? app.firstIntersection(nozzle, far) : std::nullopt;
    const Vector3d end = hit ? hit->point : Vector3d(nozzle + 0.5 * extent * dir);
    pen.line(nozzle.head<2>(), end.head<2>(), kCone, side == 0.0 ? 1.0 : 2.0, 0.6, side == 0.0 ? "6,4" : "");
  }

  for (const auto& hole : app.holes()) pen.polygon(hole, kPlate, kWall, 1.0);

  // Outer boundary: walls thick black, inlet and outlet in colour with labels.
  for (const auto& e : app.sectionEdges()) {
    if (e.kind == BoundaryKind::Plate) continue;
    const Vector2d mid = 0.5 * (e.a + e.b);
    if (e.kind == BoundaryKind::Inlet) {
      pen.line(e.a, e.b, kInlet, 5.0);
      pen.text(mid, -34.0, "gas inlet", kInlet, scale);  // below the nozzle block
    } else if (e.kind == BoundaryKind::Outlet) {
      pen.line(e.a, e.b, kOutlet, 5.0);
      pen.text(mid, 7.0, "outlet", kOutlet, scale);
    } else {
      pen.line(e.a, e.b, kWall, 4.0);
    }
  }

  // Nozzle: its head as a small block of the nozzle diameter below the tip, and a marker at the tip.
  const double dn = scene.spray.nozzle_diameter;
  const double nx = nozzle.x(), ny = nozzle.y();
  pen.polygon({{nx - dn / 2, ny - 2 * dn}, {nx + dn / 2, ny - 2 * dn}, {nx + dn / 2, ny}, {nx - dn / 2, ny}},
              kNozzle, kWall, 0.5);
  pen.circle(nozzle.head<2>(), 3.0, kNozzle);
}

}  // namespace

SvgDocument drawSection(const Scene& scene) {
  const Apparatus app(scene.apparatus);
  const CartesianGrid grid = makeGrid(app, scene.grid);
  const SprayZone zone(scene.spray.spray_zone, app);
  const Vector3d lo = app.lowerCorner(), hi = app.upperCorner();
  const double extent = std::max(hi.x() - lo.x(), hi.y() - lo.y());
  const double step = niceStep(extent / 6.0);

  // Equal scales in x and y; the legend and a detail view of the bottom sit right of the chamber.
  const double ymin = std::floor((lo.y() - 0.05 * extent) / step) * step;
  const double ymax = std::ceil((hi.y() + 0.05 * extent) / step) * step;
  const double scale = kPlotHeightPx / (ymax - ymin);  // px per metre
  const double xmin = std::floor((lo.x() - 0.05 * extent) / step) * step;
  const double legendX = hi.x() + 0.08 * extent;
  const double xmax = std::ceil((legendX + kLegendWidthPx / scale) / step) * step;
  const double widthPx = scale * (xmax - xmin) + 2 * kMarginPx;
  const double heightPx = kPlotHeightPx + 2 * kMarginPx;
  SvgDocument doc(xmin, xmax, ymin, ymax, widthPx, heightPx, kMarginPx);

  SectionPainter mainPen(doc, View{Vector2d(xmin, ymin), Vector2d(xmax, ymax), Vector2d(xmin, ymin), 1.0});
  paint(mainPen, scene, app, grid, zone, extent, scale);

  // Detail of the bottom: inlet, nozzle, spray zone and plates, magnified into the free lower right.
  const SprayZoneSpec& zs = scene.spray.spray_zone;
  double detailTop = std::max(zs.y_max, scene.spray.nozzle_position.y() + 0.05 * extent);
  double detailHalf = std::max({zone.radiusAt(zs.y_max) + std::abs(zs.apex.x()),
                                std::abs(scene.spray.nozzle_position.x()) + 0.02 * extent,
                                0.5 * (app.outline()[1].x() - app.outline()[0].x())});
  if (scene.apparatus.draft_plates) {
    const auto& dp = *scene.apparatus.draft_plates;
    detailTop = std::max(detailTop, dp.elevation + dp.height);
    detailHalf = std::max(detailHalf, 0.5 * dp.gap + dp.thickness);
  }
  detailTop += 0.1 * detailTop;
  detailHalf *= 1.4;
  const double detailBottom = lo.y() - 0.15 * detailTop;
  const Vector2d boxLo(legendX, ymin + 0.03 * (ymax - ymin));
  const Vector2d boxHi(xmax - 0.03 * (xmax - xmin), lo.y() + 0.45 * (hi.y() - lo.y()));
  const double zoom =
      std::min((boxHi.x() - boxLo.x()) / (2 * detailHalf), (boxHi.y() - boxLo.y()) / (detailTop - detailBottom));
  if (zoom > 1.5) {
    const View detail{Vector2d(-detailHalf, detailBottom), Vector2d(detailHalf, detailTop), boxLo, zoom};
    const Vector2d dHi = detail.map(detail.hi);
    doc.rect(boxLo.x(), boxLo.y(), dHi.x(), dHi.y(), "#ffffff", "#555555", 1.0);
    SectionPainter detailPen(doc, detail);
    paint(detailPen, scene, app, grid, zone, extent, scale);
    doc.rect(detail.lo.x(), detail.lo.y(), detail.hi.x(), detail.hi.y(), "none", "#555555", 1.0);
    doc.line(detail.hi.x(), detail.hi.y(), boxLo.x(), dHi.y(), "#555555", 0.8, "3,3");
    doc.text(boxLo.x(), dHi.y() + 6.0 / scale, "detail, " + fmt(zoom, 2) + "x", 11);
  }

  doc.axes("x [m]", "y [m]", int(std::lround((xmax - xmin) / step)), int(std::lround((ymax - ymin) / step)));

  // Title and a one-line summary of the dimensions.
  const Vector3d nozzle = scene.spray.nozzle_position;
  const double dn = scene.spray.nozzle_diameter;
  const ApparatusSpec& a = scene.apparatus;
  const bool box = a.type == ApparatusSpec::Type::Box;
  doc.textPx(widthPx / 2, 20, (scene.name.empty() ? std::string("scene") : scene.name) +
                                  ": x-y section at the nozzle plane z = " + fmt(nozzle.z()) + " m",
             15, "middle");
  std::string sub = box ? "box " + fmt(a.size.x()) + " x " + fmt(a.size.y()) + " x " + fmt(a.size.z()) + " m"
                        : "width " + fmt(a.width) + " m, depth " + fmt(a.depth) + " m, height " +
                              fmt(a.height) + " m, prism angle " + fmt(a.prism_angle_deg) + " deg, inlet " +
                              fmt(a.inlet_width) + " m";
  if (a.draft_plates)
    sub += "; plates " + fmt(a.draft_plates->height) + " m high, gap " + fmt(a.draft_plates->gap) +
           " m, elevation " + fmt(a.draft_plates->elevation) + " m";
  doc.textPx(widthPx / 2, 38, sub, 10, "middle");

  // Legend.
  const double rowPx = 20.0;
  double yRow = hi.y() - 0.02 * extent;
  const double x0 = legendX, x1 = legendX + 28.0 / scale, xt = legendX + 36.0 / scale;
  auto row = [&](const std::string& label) {
    doc.text(xt, yRow - 4.0 / scale, label, 11);
    yRow -= rowPx / scale;
  };
  doc.line(x0, yRow, x1, yRow, kWall, 4.0);
  row("wall");
  doc.line(x0, yRow, x1, yRow, kInlet, 5.0);
  row("gas inlet (slot " + fmt(box ? 0.0 : a.inlet_width) + " m)");
  doc.line(x0, yRow, x1, yRow, kOutlet, 5.0);
  row("outlet");
  if (a.draft_plates) {
    doc.rect(x0, yRow - 4.0 / scale, x1, yRow + 4.0 / scale, kPlate, kWall, 1.0);
    row("draft plate");
  }
  doc.circle(0.5 * (x0 + x1), yRow, 3.0, kNozzle);
  row("nozzle (d = " + fmt(dn) + " m)");
  doc.translucentLine(x0, yRow, x1, yRow, kCone, 2.0, 0.6);
  row("spray cone, " + fmt(scene.spray.cone_half_angle_deg) + " deg half-angle");
  doc.rect(x0, yRow - 5.0 / scale, x1, yRow + 5.0 / scale, kZone, kZone, 1.0, 0.3);
  row("spray zone, " + fmt(zs.y_min) + " < y < " + fmt(zs.y_max) + " m");
  doc.line(x0, yRow, x1, yRow, kGrid, 1.0);
  row("grid " + std::to_string(grid.shape[0]) + " x " + std::to_string(grid.shape[1]) + " x " +
      std::to_string(grid.shape[2]) + ", " + fmt(grid.spacing.x() * 1e3, 3) + " mm");
  yRow -= 0.5 * rowPx / scale;
  doc.text(x0, yRow, "open volume " + fmt(app.openVolume() * 1e3) + " L", 11);
  yRow -= rowPx / scale;
  doc.text(x0, yRow, "spray zone volume " + fmt(zone.volume() * 1e6) + " mL", 11);
  yRow -= rowPx / scale;
  const std::string where = zs.line_of_sight ? "  of which open and in the apex's sight " : "  of which in the open region ";
  doc.text(x0, yRow, where + fmt(zone.volumeInside(app) * 1e6) + " mL", 11);
  return doc;
}

void writeSectionSvg(const Scene& scene, const std::string& path) { drawSection(scene).save(path); }

}  // namespace rcfd
