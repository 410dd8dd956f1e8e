#pragma once
// Scenes and helpers of the coupling tests.

#include <cmath>
#include <numbers>
#include <random>

#include "cfddem/CfdDemSimulation.hpp"
#include "cfddem/coupling/DragModel.hpp"
#include "cfddem/coupling/FluidCoupling.hpp"
#include "cfddem/gas/GasSolver.hpp"
#include "../gas/GasTestSupport.hpp"

namespace rcfd::test {

/// A box with its top open (outlet), walls elsewhere, no nozzle air, the effects gas and drag.
inline Scene couplingBox(const Vec3& size, double cell, double flowRate) {
  Scene s = boxScene(size, Vec3(cell, cell, cell), flowRate);
  s.effects = {"gas", "drag"};
  return s;
}

/// The quick slice of examples/quick.json (prismatic bed, 0.02 m deep, cg 2) on its former 5 mm cells.
inline Scene quickSlice() {
  Scene s = quickSliceScene(false);
  s.process.bed_mass = 0.15;
  s.dem.coarse_graining = 2.0;
  s.dem.time_step = 1e-5;
  s.effects = {"gas", "drag", "smoothing"};
  return s;
}

/// `count` parcels at random positions of the apparatus at least `clearance` inside its walls.
inline void scatterParcels(DemSystem& dem, const Apparatus& a, long count, double clearance, std::uint64_t seed,
                           double yMax, double speed = 0.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Eigen::Vector3d lo = a.lowerCorner(), hi = a.upperCorner();
  long placed = 0;
  while (placed < count) {
    Eigen::Vector3d x = lo + (hi - lo).cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    x.y() = lo.y() + (yMax - lo.y()) * u(rng);
    if (a.signedDistance(x) < clearance) continue;  // positive inside
    const Eigen::Vector3d v = speed * Eigen::Vector3d(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
    dem.addParticle(x, v);
    ++placed;
  }
}

}  // namespace rcfd::test
