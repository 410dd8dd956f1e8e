#pragma once
/// \file SprayLaunch.hpp
/// Where a droplet parcel starts: the one rule the spray effect and the droplet-path analysis share.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "scene/Scene.hpp"

namespace rcfd {

/// A parcel's start in the spray cone of `spec`: a direction uniform in solid angle within the cone
/// around +y (cos of the half angle `cosHalfAngle`), at a distance from the nozzle tip between the
/// nozzle's radius and that plus `spread` [m]. u1, u2, u3: uniform numbers in [0, 1), drawn in this order.
inline Eigen::Vector3d sprayLaunchPoint(const SpraySpec& spec, double cosHalfAngle, double spread, double u1,
                                        double u2, double u3) {
  const double cosTheta = 1.0 - u1 * (1.0 - cosHalfAngle);
  const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
  const double phi = 2.0 * std::numbers::pi * u2;
  const Eigen::Vector3d dir(sinTheta * std::cos(phi), cosTheta, sinTheta * std::sin(phi));
  const double r = 0.5 * spec.nozzle_diameter + spread * u3;
  return spec.nozzle_position + r * dir;
}

}  // namespace rcfd
