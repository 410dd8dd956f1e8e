#pragma once
/// \file TracerCloud.hpp
/// Lagrangian tracers as a structure of arrays. Each tracer stands for `particlesPerTracer` real
/// particles of the bed. Positions and velocities are double: tracers are stepped 720,000 times in a
/// 1 h run and the arrays (48 B per tracer) are small next to the field frames. The simulation keeps
/// the tracers sorted by cell (TracerSimulation::sortTracers) for the memory locality of the field
/// reads, so a tracer's index changes; `id` is its identity (random streams, per-tracer results).

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
    id.resize(n);
    for (std::size_t i = 0; i < n; ++i) id[i] = std::int32_t(i);
  }
  std::size_t size() const { return x.size(); }

  Eigen::Vector3d position(std::size_t i) const { return {x[i], y[i], z[i]}; }
  void setPosition(std::size_t i, const Eigen::Vector3d& p) { x[i] = p.x(), y[i] = p.y(), z[i] = p.z(); }
  Eigen::Vector3d velocity(std::size_t i) const { return {vx[i], vy[i], vz[i]}; }
  void setVelocity(std::size_t i, const Eigen::Vector3d& v) { vx[i] = v.x(), vy[i] = v.y(), vz[i] = v.z(); }

  std::vector<double> x, y, z;     ///< position [m]
  std::vector<double> vx, vy, vz;  ///< velocity of the last step [m/s]; kept only with free_flight, its one reader (0 otherwise)
  std::vector<std::int32_t> id;    ///< identity of the tracer at each index (0 .. size-1, a permutation)
  /// values[i] given per index, returned per id (per-tracer results are written in id order).
  template <class T>
  std::vector<T> inIdOrder(const std::vector<T>& values) const {
    std::vector<T> out(values.size());
    for (std::size_t i = 0; i < values.size(); ++i) out[std::size_t(id[i])] = values[i];
    return out;
  }
  double particlesPerTracer = 1.0; ///< real particles represented by one tracer [-]
  double particleVolume = 0.0;     ///< volume of one real particle [m3]
};

}  // namespace rcfd
