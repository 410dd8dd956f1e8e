// A single particle settling in still gas reaches the terminal velocity of the drag balance
// m g (1 - rho_G / rho_P) = 3 pi mu d eps F(eps, Re) v (Beetstra at eps ~ 1).

#include <gtest/gtest.h>

#include "CouplingTestSupport.hpp"

namespace rcfd {
namespace {

// d = 100 um, rho 1040 kg/m3 in air: v_t = 0.27 m/s, Re = 1.8, relaxation time 28 ms; 0.2 s (7
// relaxation times) leaves 0.1% of the start-up. 1 cm cells: the particle fills 5e-7 of its cell, and
// the momentum it gives the gas over the run moves a cell's gas by ~1 mm/s (0.3% of v_t).
TEST(SingleParticle, TerminalVelocityWithinTwoPercentOfTheDragBalance) {
  Scene s = test::couplingBox(Vec3(0.04, 0.10, 0.04), 0.01, 0.0);
  s.particles.diameter = 1e-4;
  s.dem.time_step = 1e-6;
  s.dem.coupling_interval = 100;
  s.gas.max_time_step = 1e-4;
  CfdDemSimulation sim(s, 1);
  sim.dem().addParticle(Eigen::Vector3d(0.0, 0.09, 0.02));
  while (sim.time() < 0.2 - 1e-12) sim.step(sim.demStep() + 100);
  const double v = -sim.dem().particles().v[0].y();
  const double rhoG = s.gas.density, nu = s.gas.kinematic_viscosity, mu = rhoG * nu, d = s.particles.diameter;
  const double m = s.particles.density * std::numbers::pi / 6 * d * d * d;
  const double weight = m * 9.81 * (1 - rhoG / s.particles.density);
  const double eps = 1 - std::numbers::pi / 6 * d * d * d / 1e-6;
  double lo = 0.0, hi = 10.0;  // bisection of the balance
  for (int it = 0; it < 200; ++it) {
    const double u = 0.5 * (lo + hi);
    const double drag = 3 * std::numbers::pi * mu * d * eps * coupling::beetstraDrag(eps, d * eps * u / nu) * u;
    (drag > weight ? hi : lo) = u;
  }
  RecordProperty("terminal_velocity_over_balance", std::to_string(v / lo));
  EXPECT_NEAR(v, lo, 0.02 * lo) << "balance " << lo << " m/s";
  EXPECT_LT(std::abs(sim.dem().particles().v[0].x()), 1e-3 * v);
}

}  // namespace
}  // namespace rcfd
