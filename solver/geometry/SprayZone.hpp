#pragma once
/// \file SprayZone.hpp
/// The fictitious spray zone of the paper's Fig. 2: a cone with its apex at the nozzle, axis +y and a
/// given half-angle, cut to y_min <= y <= y_max (a truncated cone). Residence times and holdups are
/// counted in it. With `line_of_sight` the draft plates shadow it: a point counts only when the straight
/// line from the apex reaches it without crossing a plate, as the spray does.

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "scene/Scene.hpp"

namespace rcfd {

class Apparatus;

class SprayZone {
 public:
  /// Throws rcfd::InputError naming /spray/spray_zone/... when the half-angle is not in (0, 90) deg,
  /// y_min >= y_max, or the cut starts below the apex (y_min < apex.y: the cone has one nappe).
  /// A free cone: nothing shadows it, whatever `line_of_sight` says.
  explicit SprayZone(const SprayZoneSpec& spec);
  /// The cone in the apparatus: with `line_of_sight` the apparatus's draft plates shadow it.
  SprayZone(const SprayZoneSpec& spec, const Apparatus& apparatus);

  const SprayZoneSpec& spec() const { return spec_; }

  /// True if p lies in the truncated cone (boundary included) and, with `line_of_sight`, is not in a
  /// plate's shadow.
  bool contains(const Eigen::Vector3d& p) const { return contains(p.x(), p.y(), p.z()); }
  /// The same test on coordinates.
  bool contains(double x, double y, double z) const {
    return shadows_.empty() ? inCone(x, y, z) : inCone(x, y, z) && !shadowed(x, y);
  }

  /// The truncated cone alone, branch-free, so loops over many points vectorise; with hasShadows() the
  /// points it accepts are then tested with shadowed().
  bool inCone(double x, double y, double z) const {
    const double dx = x - spec_.apex.x(), dz = z - spec_.apex.z();
    const double above = y - spec_.apex.y();
    const double r = (above > 0.0 ? above : 0.0) * tanHalfAngle_;  // radiusAt(y)
    return (y >= spec_.y_min) & (y <= spec_.y_max) & (dx * dx + dz * dz <= r * r);
  }
  /// True if plates shadow the zone (`line_of_sight` and a plate between y_min and y_max).
  bool hasShadows() const { return !shadows_.empty(); }
  /// True if the segment from the apex to (x, y) (any z: the plates span the depth) meets a plate.
  bool shadowed(double x, double y) const;

  /// Radius of the cone's cross-section at height y, (y - apex.y) tan(half-angle) [m]; 0 below the apex.
  double radiusAt(double y) const;

  /// Exact volume of the truncated cone [m3], pi tan^2(a) / 3 ((y_max - y_a)^3 - (y_min - y_a)^3).
  /// The apparatus is ignored: a zone reaching through a wall keeps its full volume.
  double volume() const;

  /// Volume of the part of the zone inside the apparatus's open region [m3]: exact disk-rectangle
  /// areas per height, integrated over y by composite Simpson with `slices` steps (relative error
  /// ~1e-8 at the default). Differs from volume() when the zone reaches through the z faces (thin
  /// pseudo-2D slices), the V walls or the draft plates.
  /// With `line_of_sight`, the shadows of the plates this zone was built with are left out as well.
  double volumeInside(const Apparatus& apparatus, int slices = 4000) const;

 private:
  /// A plate's rectangle in the x-y section [m].
  struct Shadow {
    double x0, x1, y0, y1;
  };
  /// The x-interval at height y that the segment from the apex crosses `plate` to reach; empty (lo > hi)
  /// where it does not.
  std::pair<double, double> shadowAt(const Shadow& plate, double y) const;

  SprayZoneSpec spec_;
  double tanHalfAngle_ = 0.0;
  std::vector<Shadow> shadows_;  ///< the plates that shadow the zone (empty without line_of_sight)
};

}  // namespace rcfd
