// Gas phase against analytic solutions: plane Poiseuille flow, a uniform stream through a uniform
// alpha_G, and the Ergun pressure drop of a fixed packed bed.

#include <gtest/gtest.h>

#include <cmath>

#include "GasTestSupport.hpp"

namespace rcfd {
namespace {

using test::boxScene;
using test::GasCase;

// A channel of width H between two no-slip walls (x = +-H/2), free-slip front and back (plane flow),
// fed by a uniform stream through the bottom, open at the top. Far from the inlet the profile is the
// parabola u = 1.5 U (1 - (2x/H)^2). Re = U H / nu = 5: the entrance length (~0.6 H + 0.05 Re H) is
// below 1 cm; the profile is checked 2.5 cm up.
TEST(GasVerification, PlanePoiseuilleProfileWithinOnePercent) {
  const double H = 0.01, depth = 0.001, U = 0.0075;
  Scene s = boxScene(Vec3(H, 0.04, depth), Vec3(H / 20, 0.001, depth), U * H * depth);
  s.gas.max_time_step = 1.0;  // the viscous bound sets dt here
  gas::GasOptions o;
  o.slipFrontBack = true;
  o.boxBottomInlet = true;
  GasCase c(s, o);
  auto& g = *c.solver;
  // Slowest viscous mode decays like exp(-pi^2 nu t / H^2) = exp(-1.48 t/s): 8 s leaves ~1e-5.
  while (g.time() < 8.0) g.step(1.0);
  const auto& v = g.faceVelocity(1);
  const auto& shape = g.apertures().shape[1];
  const int j = 25;  // face at y = 25 mm
  double maxErr = 0.0;
  for (int i = 0; i < shape[0]; ++i) {
    const double x = c.grid.cellCenter(i, 0, 0).x();
    const double exact = 1.5 * U * (1 - std::pow(2 * x / H, 2));
    const double got = v[std::size_t(j) * shape[0] + i];
    maxErr = std::max(maxErr, std::abs(got - exact));
  }
  RecordProperty("max_error_over_peak", std::to_string(maxErr / (1.5 * U)));
  RecordProperty("dpdy_over_exact", std::to_string(g.pressureGradientAt(Eigen::Vector3d(0.0, 0.025, 0.5 * depth)).y() /
                                                   (-12 * s.gas.density * s.gas.kinematic_viscosity * U / (H * H))));
  EXPECT_LT(maxErr, 0.01 * 1.5 * U) << "largest deviation from the parabola " << maxErr << " m/s";
  // Fully developed: the pressure gradient is the Poiseuille one, dp/dy = -12 mu U / H^2.
  const double mu = s.gas.density * s.gas.kinematic_viscosity;
  const double dpdy = g.pressureGradientAt(Eigen::Vector3d(0.0, 0.025, 0.5 * depth)).y();
  EXPECT_NEAR(dpdy, -12 * mu * U / (H * H), 0.02 * 12 * mu * U / (H * H));
}

// Uniform alpha_G = 0.5 with frictionless walls: the stream stays uniform at the interstitial velocity
// U / alpha_G, with no lateral velocity.
TEST(GasVerification, UniformStreamThroughUniformAlphaStaysUniform) {
  const double U = 1.0;
  Scene s = boxScene(Vec3(0.05, 0.1, 0.02), Vec3(0.005, 0.005, 0.005), U * 0.05 * 0.02);
  gas::GasOptions o;
  o.slipFrontBack = o.slipSideWalls = o.boxBottomInlet = true;
  GasCase c(s, o);
  auto& g = *c.solver;
  g.setGasFraction(std::vector<double>(std::size_t(c.grid.cellCount()), 0.5));
  for (int n = 0; n < 50; ++n) g.step(1.0);
  for (const auto& u : g.cellVelocity()) {
    ASSERT_NEAR(u.y(), U / 0.5, 1e-6);
    ASSERT_NEAR(u.x(), 0.0, 1e-6);
    ASSERT_NEAR(u.z(), 0.0, 1e-6);
  }
  EXPECT_NEAR(g.velocityAt(Eigen::Vector3d(0.01, 0.05, 0.01)).y(), 2.0, 1e-6);
}

// A fixed bed (alpha_G = 0.4, 1.8 mm particles, 5 cm high) in a frictionless column at U = 0.5 m/s.
// The test passes an Ergun-form drag, beta (u_G - u_P) with beta = alpha_G eps (A + B eps |u_G|), which
// makes -dp/dy = A U + B U^2 (U = eps u_G superficial) in a uniform bed; the solver's pressure drop
// must reproduce the Ergun equation (the bed) within 10%.
TEST(GasVerification, PackedBedPressureDropMatchesErgun) {
  const double U = 0.5, eps = 0.4, d = 1.8e-3, y0 = 0.05, y1 = 0.10;
  Scene s = boxScene(Vec3(0.02, 0.2, 0.01), Vec3(0.005, 0.005, 0.005), U * 0.02 * 0.01);
  s.gas.max_time_step = 1e-3;
  gas::GasOptions o;
  o.slipFrontBack = o.slipSideWalls = o.boxBottomInlet = true;
  GasCase c(s, o);
  auto& g = *c.solver;
  const double rho = s.gas.density, mu = rho * s.gas.kinematic_viscosity;
  const double A = 150 * mu * (1 - eps) * (1 - eps) / (eps * eps * eps * d * d);
  const double B = 1.75 * rho * (1 - eps) / (eps * eps * eps * d);
  const std::size_t n = std::size_t(c.grid.cellCount());
  std::vector<double> alpha(n, 1.0);
  std::vector<char> inBed(n, 0);
  for (std::size_t k = 0; k < n; ++k) {
    const auto ijk = c.grid.cellIjk(std::int64_t(k));
    const double y = c.grid.cellCenter(ijk[0], ijk[1], ijk[2]).y();
    if (y > y0 && y < y1) alpha[k] = eps, inBed[k] = 1;
  }
  g.setGasFraction(alpha);
  std::vector<double> beta(n, 0.0);
  const std::vector<Eigen::Vector3d> uP(n, Eigen::Vector3d::Zero());
  for (int step = 0; step < 200; ++step) {
    const auto u = g.cellVelocity();
    for (std::size_t k = 0; k < n; ++k) beta[k] = inBed[k] ? eps * eps * (A + B * eps * u[k].norm()) : 0.0;
    g.setDragSource(beta, uP);
    g.step(1.0);
  }
  const double ergun = (A * U + B * U * U) * (y1 - y0);
  RecordProperty("pressure_drop_over_ergun", std::to_string(g.pressureDrop() / ergun));
  EXPECT_NEAR(g.pressureDrop(), ergun, 0.1 * ergun) << "Ergun " << ergun << " Pa";
  EXPECT_NEAR(-g.pressureGradientAt(Eigen::Vector3d(0.0, 0.075, 0.005)).y(), ergun / (y1 - y0),
              0.1 * ergun / (y1 - y0));
  // The gas flux is U everywhere: interstitial U / eps in the bed.
  EXPECT_NEAR(g.velocityAt(Eigen::Vector3d(0.0, 0.075, 0.005)).y(), U / eps, 1e-6);
}

}  // namespace
}  // namespace rcfd
