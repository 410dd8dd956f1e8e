#include "geometry/SprayZone.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "core/Errors.hpp"

namespace rcfd {
namespace {
std::string fmt(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
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

double SprayZone::radiusAt(double y) const {
  return y <= spec_.apex.y() ? 0.0 : (y - spec_.apex.y()) * tanHalfAngle_;
}

bool SprayZone::contains(const Eigen::Vector3d& p) const {
  if (p.y() < spec_.y_min || p.y() > spec_.y_max) return false;
  const double dx = p.x() - spec_.apex.x(), dz = p.z() - spec_.apex.z();
  const double r = radiusAt(p.y());
  return dx * dx + dz * dz <= r * r;
}

double SprayZone::volume() const {
  const double h1 = spec_.y_max - spec_.apex.y(), h0 = spec_.y_min - spec_.apex.y();
  return std::numbers::pi * tanHalfAngle_ * tanHalfAngle_ / 3.0 * (h1 * h1 * h1 - h0 * h0 * h0);
}

}  // namespace rcfd
