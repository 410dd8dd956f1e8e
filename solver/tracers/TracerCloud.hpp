#pragma once
/// \file TracerCloud.hpp
/// Lagrangian tracers as a structure of arrays. Each tracer stands for `particlesPerTracer` real
/// particles of the bed. Positions and velocities are double: tracers are stepped 720,000 times in a
/// 1 h run and the arrays (48 B per tracer) are small next to the field frames.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace rcfd {

class TracerCloud {
 public:
  TracerCloud() = default;
  explicit TracerCloud(std::size_t n) { resize(n); }

  void resize(std::size_t n) {
    x.assign(n, 0.0), y.assign(n, 0.0), z.assign(n, 0.0);
    vx.assign(n, 0.0), vy.assign(n, 0.0), vz.assign(n, 0.0);
  }
  std::size_t size() const { return x.size(); }

  Eigen::Vector3d position(std::size_t i) const { return {x[i], y[i], z[i]}; }
  void setPosition(std::size_t i, const Eigen::Vector3d& p) { x[i] = p.x(), y[i] = p.y(), z[i] = p.z(); }
  Eigen::Vector3d velocity(std::size_t i) const { return {vx[i], vy[i], vz[i]}; }
  void setVelocity(std::size_t i, const Eigen::Vector3d& v) { vx[i] = v.x(), vy[i] = v.y(), vz[i] = v.z(); }

  std::vector<double> x, y, z;     ///< position [m]
  std::vector<double> vx, vy, vz;  ///< velocity of the last step [m/s]; kept only with free_flight, its one reader (0 otherwise)
  double particlesPerTracer = 1.0; ///< real particles represented by one tracer [-]
  double particleVolume = 0.0;     ///< volume of one real particle [m3]
};

}  // namespace rcfd
