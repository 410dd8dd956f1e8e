#include "geometry/SectionFigure.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

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

/// 1, 2 or 5 times a power of ten, close to `raw`.
double niceStep(double raw) {
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / p;
  return (f < 1.5 ? 1.0 : f < 3.5 ? 2.0 : f < 7.5 ? 5.0 : 10.0) * p;
}

}  // namespace

SvgDocument drawSection(const Scene& scene) {
  const Apparatus app(scene.apparatus);
  const CartesianGrid grid = makeGrid(app, scene.grid);
  const SprayZone zone(scene.spray.spray_zone);
  const Vector3d lo = app.lowerCorner(), hi = app.upperCorner();
  const double extent = std::max(hi.x() - lo.x(), hi.y() - lo.y());
  const double step = niceStep(extent / 6.0);

  // Equal scales in x and y; the legend sits right of the chamber inside the axis box.
  const double ymin = std::floor((lo.y() - 0.05 * extent) / step) * step;
  const double ymax = std::ceil((hi.y() + 0.05 * extent) / step) * step;
  const double scale = kPlotHeightPx / (ymax - ymin);  // px per metre
  const double xmin = std::floor((lo.x() - 0.05 * extent) / step) * step;
  const double legendX = hi.x() + 0.08 * extent;
  const double xmax = std::ceil((legendX + kLegendWidthPx / scale) / step) * step;
  const double widthPx = scale * (xmax - xmin) + 2 * kMarginPx;
  const double heightPx = kPlotHeightPx + 2 * kMarginPx;
  SvgDocument doc(xmin, xmax, ymin, ymax, widthPx, heightPx, kMarginPx);

  // Open region, lightly tinted, then the grid lines over it.
  std::vector<std::array<double, 2>> outline;
  for (const auto& p : app.outline()) outline.push_back({p.x(), p.y()});
  doc.polygon(outline, kOpen);
  const Vector3d gHi = grid.upperCorner();
  for (int i = 0; i <= grid.shape[0]; ++i) {
    const double x = grid.origin.x() + i * grid.spacing.x();
    doc.line(x, grid.origin.y(), x, gHi.y(), kGrid, 0.5);
  }
  for (int j = 0; j <= grid.shape[1]; ++j) {
    const double y = grid.origin.y() + j * grid.spacing.y();
    doc.line(grid.origin.x(), y, gHi.x(), y, kGrid, 0.5);
  }

  // Spray zone: its axial section, a trapezoid (exact in the plane z = apex.z).
  const SprayZoneSpec& zs = scene.spray.spray_zone;
  const double r0 = zone.radiusAt(zs.y_min), r1 = zone.radiusAt(zs.y_max);
  doc.polygon({{zs.apex.x() - r0, zs.y_min}, {zs.apex.x() + r0, zs.y_min}, {zs.apex.x() + r1, zs.y_max},
               {zs.apex.x() - r1, zs.y_max}},
              kZone, kZone, 1.0, 0.3);

  // Spray cone: rays from the nozzle at +-half-angle until they meet a wall, plate or the outlet.
  const Vector3d nozzle = scene.spray.nozzle_position;
  const double half = scene.spray.cone_half_angle_deg * std::numbers::pi / 180.0;
  for (double side : {-1.0, 0.0, 1.0}) {
    const Vector3d dir(side * std::sin(half), side == 0.0 ? 1.0 : std::cos(half), 0.0);
    const Vector3d far = nozzle + 2.0 * extent * dir;
    const auto hit = app.contains(nozzle) ? app.firstIntersection(nozzle, far) : std::nullopt;
    const Vector3d end = hit ? hit->point : Vector3d(nozzle + 0.5 * extent * dir);
    if (side == 0.0) {
      doc.translucentLine(nozzle.x(), nozzle.y(), end.x(), end.y(), kCone, 1.0, 0.6, "6,4");
    } else {
      doc.translucentLine(nozzle.x(), nozzle.y(), end.x(), end.y(), kCone, 2.0, 0.6);
    }
  }

  // Draft plates.
  for (const auto& hole : app.holes()) {
    std::vector<std::array<double, 2>> pts;
    for (const auto& p : hole) pts.push_back({p.x(), p.y()});
    doc.polygon(pts, kPlate, kWall, 1.0);
  }

  // Outer boundary: walls thick black, inlet and outlet in colour with labels.
  const double labelGap = 12.0 / scale;
  for (const auto& e : app.sectionEdges()) {
    if (e.kind == BoundaryKind::Plate) continue;
    const Vector2d mid = 0.5 * (e.a + e.b);
    if (e.kind == BoundaryKind::Inlet) {
      doc.line(e.a.x(), e.a.y(), e.b.x(), e.b.y(), kInlet, 5.0);
      doc.text(mid.x(), mid.y() - 1.6 * labelGap, "gas inlet", 12, "middle", kInlet);
    } else if (e.kind == BoundaryKind::Outlet) {
      doc.line(e.a.x(), e.a.y(), e.b.x(), e.b.y(), kOutlet, 5.0);
      doc.text(mid.x(), mid.y() + 0.6 * labelGap, "outlet", 12, "middle", kOutlet);
    } else {
      doc.line(e.a.x(), e.a.y(), e.b.x(), e.b.y(), kWall, 4.0);
    }
  }

  // Nozzle: its head as a small block of the nozzle diameter below the tip, and a marker at the tip.
  const double dn = scene.spray.nozzle_diameter;
  doc.rect(nozzle.x() - dn / 2, nozzle.y() - 2 * dn, nozzle.x() + dn / 2, nozzle.y(), kNozzle, kWall, 0.5);
  doc.circle(nozzle.x(), nozzle.y(), 3.0, kNozzle);

  doc.axes("x [m]", "y [m]", int(std::lround((xmax - xmin) / step)), int(std::lround((ymax - ymin) / step)));

  // Title and a one-line summary of the dimensions.
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
  return doc;
}

void writeSectionSvg(const Scene& scene, const std::string& path) { drawSection(scene).save(path); }

}  // namespace rcfd
