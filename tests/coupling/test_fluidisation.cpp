// The minimum fluidisation velocity of a flat bed of the paper's particles (1.8 mm, 1040 kg/m3) in a
// small box fed through its whole bottom: the gas is ramped and U_mf is where the bed pressure drop
// first carries the bed weight per area. Against the Wen-Yu correlation, within 20%.

#include <gtest/gtest.h>

#include <cstdlib>
#include <iostream>

#include "CouplingTestSupport.hpp"

namespace rcfd {
namespace {

void printBed(const CfdDemSimulation& sim) {
  const auto a = sim.particleFraction();
  const auto u = sim.gasVelocity();
  const auto& g = sim.grid();
  for (int j = 0; j < g.shape[1]; ++j) {
    std::cerr << "j " << j << ":";
    for (int i = 0; i < g.shape[0]; ++i)
      std::cerr << " " << a[std::size_t(g.flatIndex(i, j, 3))] << "/" << u[std::size_t(g.flatIndex(i, j, 3))].y();
    std::cerr << "\n";
  }
  const Scene& sc = sim.scene();
  const double mu = sc.gas.density * sc.gas.kinematic_viscosity, d = sc.particles.diameter;
  const auto& pr = sim.gasSolver()->pressure();
  for (int j = 0; j + 1 < g.shape[1]; ++j) {
    const std::size_t c = std::size_t(g.flatIndex(2, j, 2)), c1 = std::size_t(g.flatIndex(2, j + 1, 2));
    const double eps = 1 - a[c], us = eps * u[c].y();
    const double G = 18 * mu * a[c] * coupling::beetstraDrag(eps, d * us / sc.gas.kinematic_viscosity) * us / (eps * d * d);
    std::cerr << "col j " << j << " aP " << a[c] << " uy " << u[c].y() << " -dp/dy " << (pr[c] - pr[c1]) / 0.005
              << " beetstra " << G << " beta " << sim.fluidCoupling()->beta()[c] << "\n";
  }
}

// A 5 cm x 5 cm box (14 parcel diameters: in a narrower one the looser packing along the walls lets
// the gas bypass the core and U_mf rises), cg 2 parcels of 3.6 mm in 5 mm cells as in quick.json. The
// bed is poured and settled (DEM only, as in the database job); the gas then rises to
// 0.2 m/s in 0.05 s and ramps on to 0.9 m/s in 0.5 s (below U_mf the bed does not move, so the ramp may
// be fast). The pressure drop is extrapolated from the two lowest cell rows to the inlet face.
TEST(Fluidisation, MinimumFluidisationVelocityWithinTwentyPercentOfWenYu) {
  const double uMax = 0.9, uStart = 0.2, width = 0.05, startTime = 0.05, rampTime = 0.5;
  Scene s = test::couplingBox(Vec3(width, 0.08, width), 0.005, uMax * width * width);
  s.dem.coarse_graining = 2.0;
  s.dem.time_step = 4e-5;  // 0.28 of the Rayleigh time of the 3.6 mm parcels
  s.dem.coupling_interval = 10;
  s.gas.max_time_step = 4e-4;
  s.dem.settle_time = 0.15;
  s.process.bed_mass = 0.04;  // 1570 parcels, a bed about 2.6 cm high
  s.effects = {"gas", "drag", "rolling_friction"};
  if (std::getenv("RCFD_SMOOTHING")) s.effects.push_back("smoothing");
  gas::GasOptions go;
  go.boxBottomInlet = true;
  CfdDemSimulation sim(s, 5, go);
  sim.setFlowFactor(0.0);
  sim.fillAndSettle();  // poured in batches and settled with the gas off (DemFilling)
  const DemParticles& p = sim.dem().particles();
  double weight = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) weight += p.mass[i] * 9.81 * (1 - s.gas.density / s.particles.density);
  const double target = weight / (width * width);  // [Pa]
  const double hydrostatic = s.gas.density * 9.81 * s.apparatus.size.y();
  const bool debug = std::getenv("RCFD_DEBUG") != nullptr;
  const auto& g = sim.grid();
  auto inletPressure = [&] {  // area mean of the two lowest rows, extrapolated to y = 0
    const auto& pr = sim.gasSolver()->pressure();
    double p0 = 0.0, p1 = 0.0;
    for (int k = 0; k < g.shape[2]; ++k)
      for (int i = 0; i < g.shape[0]; ++i) {
        p0 += pr[std::size_t(g.flatIndex(i, 0, k))];
        p1 += pr[std::size_t(g.flatIndex(i, 1, k))];
      }
    const double n = double(g.shape[0] * g.shape[2]);
    return (1.5 * p0 - 0.5 * p1) / n;
  };
  const double t0 = sim.time();
  double uMf = -1.0;
  int steps = 0;
  while (sim.time() - t0 < startTime + rampTime) {
    const double t = sim.time() - t0;
    const double u = t < startTime ? uStart * t / startTime : uStart + (uMax - uStart) * (t - startTime) / rampTime;
    sim.setFlowFactor(std::min(1.0, u / uMax));
    sim.step(sim.demStep() + s.dem.coupling_interval);
    const double dp = inletPressure() - hydrostatic;
    if (debug && ++steps % 50 == 0) std::cerr << "U " << u << " dp " << dp << " target " << target << "\n";
    if (debug && steps == 200) printBed(sim);
    if (t > startTime && dp >= target) {
      uMf = u;
      break;
    }
  }
  const double rhoG = s.gas.density, mu = rhoG * s.gas.kinematic_viscosity, d = s.particles.diameter;
  const double ar = d * d * d * rhoG * (s.particles.density - rhoG) * 9.81 / (mu * mu);
  const double wenYu = (std::sqrt(33.7 * 33.7 + 0.0408 * ar) - 33.7) * mu / (rhoG * d);
  RecordProperty("umf_over_wen_yu", std::to_string(uMf / wenYu));
  ASSERT_GT(uMf, 0.0) << "the bed pressure drop never reached the bed weight " << target << " Pa";
  EXPECT_NEAR(uMf, wenYu, 0.2 * wenYu) << "Wen-Yu " << wenYu << " m/s";
}

}  // namespace
}  // namespace rcfd
