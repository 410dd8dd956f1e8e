// Gas phase in the ProCell apparatus: inlet and nozzle set-up, mass conservation with and without draft
// plates, the continuity residual under a moving alpha_G, stability at the CFL limit, refused input.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include "GasTestSupport.hpp"
#include "../ScopedVariable.hpp"
#include "cfddem/gas/FaceApertures.hpp"
#include "core/Errors.hpp"
#include "core/Isa.hpp"

namespace rcfd {
namespace {

using test::GasCase;
using test::quickSliceScene;

TEST(GasProCell, InletAndNozzleCarryTheSceneFlows) {
  GasCase c(quickSliceScene(false));
  const auto& g = *c.solver;
  // The slot is inlet_width x depth = 0.02 m x 0.02 m: 0.0063889 m3/s gives 15.97 m/s.
  EXPECT_NEAR(g.inletVelocity(), 0.0063889 / (0.02 * 0.02), 1e-9);
  EXPECT_NEAR(g.inletFlow(), 0.0063889, 1e-15);
  EXPECT_NEAR(g.nozzleFlow(), 0.00013889, 1e-15);
  // Apertures: a vertical segment crossing the right V wall (60 deg through (0.01, 0)) at x = 0.02 is
  // open above y = 0.01 tan 60.
  const double yWall = 0.01 * std::tan(std::numbers::pi / 3);
  EXPECT_NEAR(gas::openSegmentLength(c.apparatus, {0.02, 0.0}, {0.02, 0.03}), 0.03 - yWall, 1e-14);
  // Inside a plate: the plate (x from 0.0225 to 0.0245, y from 0.035 to 0.095) removes its thickness (the V wall is at x = 0.062 at y = 0.09).
  Apparatus withPlates(quickSliceScene(true).apparatus);
  EXPECT_NEAR(gas::openSegmentLength(withPlates, {0.0, 0.09}, {0.05, 0.09}), 0.05 - 0.002, 1e-14);
}

/// balance: allowed |net outflow - nozzle flow| relative to the total flow. The sum of the cell residuals
/// is bounded by the relative L2 stopping test only up to sqrt(cells): multigrid ends with a near
/// zero-sum residual (1e-14 q), incomplete Cholesky or Jacobi with up to 4e-7 q (IC, draft plates as
/// baffles, step 3) while every cell meets the tolerance.
void expectMassConserved(bool plates, const std::string& preconditioner = "mg", double balance = 1e-7) {
  Scene scene = quickSliceScene(plates);
  scene.gas.pressure_preconditioner = preconditioner;
  GasCase c(scene);
  auto& g = *c.solver;
  const double q = c.scene.process.gas_flow_rate + c.scene.process.atomisation_flow_rate;
  for (int n = 0; n < 15; ++n) {
    g.step(1.0);
    ASSERT_LE(g.lastStep().divergence.relative, c.scene.gas.pressure_tolerance) << "step " << n;
    // Outflow at the top = slot + nozzle (alpha_G constant: no storage).
    ASSERT_NEAR(g.netOutflow(), g.nozzleFlow(), balance * q) << "step " << n;
  }
  EXPECT_NEAR(g.inletFlow(), c.scene.process.gas_flow_rate, 1e-12);
  // Closed faces carry no velocity.
  for (int d = 0; d < 3; ++d)
    for (std::size_t f = 0; f < g.faceKinds(d).size(); ++f)
      if (g.faceKinds(d)[f] == gas::GasSolver::Closed) {
        ASSERT_EQ(g.faceVelocity(d)[f], 0.0);
      }
}

TEST(GasProCell, MassConservedWithoutPlates) { expectMassConserved(false); }

// The face-rate row loop in every variant this CPU runs (core/Isa.hpp): the same flow through the slice
// with its plates after 15 steps, to round-off (they agree bit for bit on the machines measured).
TEST(GasProCell, EveryKernelVariantGivesTheSameFlow) {
  std::vector<std::vector<double>> first;
  Isa firstIsa = Isa::native;
  for (Isa isa : builtIsas()) {
    if (!cpuRuns(isa)) continue;
    const test::ScopedVariable variant("RCFD_ISA", isaName(isa));
    GasCase c(quickSliceScene(true));
    for (int n = 0; n < 15; ++n) c.solver->step(1.0);
    std::vector<std::vector<double>> u;
    for (int d = 0; d < 3; ++d) u.push_back(c.solver->faceVelocity(d));
    if (first.empty()) {
      first = u, firstIsa = isa;
      continue;
    }
    double scale = 0.0, worst = 0.0;
    for (int d = 0; d < 3; ++d)
      for (std::size_t f = 0; f < u[std::size_t(d)].size(); ++f) {
        scale = std::max(scale, std::abs(first[std::size_t(d)][f]));
        worst = std::max(worst, std::abs(u[std::size_t(d)][f] - first[std::size_t(d)][f]));
      }
    std::cout << isaName(isa) << " against " << isaName(firstIsa) << ": largest difference " << worst
              << " m/s of " << scale << " m/s\n";
    EXPECT_LE(worst, 1e-12 * scale) << isaName(isa);
    EXPECT_GT(scale, 1.0);
  }
}
TEST(GasProCell, MassConservedWithPlates) { expectMassConserved(true); }
TEST(GasProCell, MassConservedWithIncompleteCholeskyAndJacobi) {
  expectMassConserved(true, "ic", 1e-6);
  expectMassConserved(false, "jacobi");
}

// A bubble of low alpha_G rising and breathing through the bed region: every step, the discrete
// Eq. (1) residual is below the pressure tolerance, and the global balance includes the storage term.
TEST(GasProCell, DivergenceBelowToleranceWithMovingAlpha) {
  GasCase c(quickSliceScene(false));
  auto& g = *c.solver;
  const std::size_t n = std::size_t(c.grid.cellCount());
  std::vector<double> alpha(n);
  for (int step = 0; step < 15; ++step) {
    const double t = g.time();
    const Eigen::Vector3d centre(0.01 * std::sin(2000 * t), 0.05 + 200 * t, 0.01);
    for (std::size_t k = 0; k < n; ++k) {
      const auto ijk = c.grid.cellIjk(std::int64_t(k));
      const double r2 = (c.grid.cellCenter(ijk[0], ijk[1], ijk[2]) - centre).squaredNorm();
      alpha[k] = 1.0 - (0.45 + 0.1 * std::sin(3000 * t)) * std::exp(-r2 / (0.02 * 0.02));
    }
    g.setGasFraction(alpha);
    g.step(1.0);
    ASSERT_LE(g.lastStep().divergence.relative, c.scene.gas.pressure_tolerance) << "step " << step;
    ASSERT_LE(g.lastStep().divergence.net, c.scene.gas.pressure_tolerance) << "step " << step;
    ASSERT_GT(std::abs(g.storageRate()), 1e-5) << "alpha_G does change";
    const double q = c.scene.process.gas_flow_rate;
    ASSERT_NEAR(g.netOutflow(), g.nozzleFlow() - g.storageRate(), 1e-7 * q) << "step " << step;
  }
}

// 230 m3/h scaled to the slice (16 m/s in the slot) with the time step at the CFL limit only. 10 mm
// cells (the slot is two cells wide) to keep the test short; the step is CFL-bound all the same.
TEST(GasProCell, StableAtTheCflLimit) {
  Scene s = quickSliceScene(true);
  s.gas.max_time_step = 1.0;
  s.grid.cell_size = Vec3(0.01, 0.01, 0.01);
  GasCase c(s);
  auto& g = *c.solver;
  for (int n = 0; n < 400; ++n) {
    g.step(1.0);
    // The first steps accelerate the flow from rest: the velocity after the step exceeds the one that
    // chose dt. Afterwards the step keeps the Courant number at the scene's cfl.
    if (n > 5) {
      ASSERT_LE(g.lastStep().courant, 1.2 * s.gas.cfl) << "step " << n;
    }
  }
  double uMax = 0.0;
  for (const auto& u : g.cellVelocity()) uMax = std::max(uMax, u.norm());
  EXPECT_LT(uMax, 3 * g.inletVelocity()) << "t = " << g.time() << " s";
  EXPECT_GT(g.time(), 0.05);
  // The jet has reached 10 cm: the spout is there.
  EXPECT_GT(g.velocityAt(Eigen::Vector3d(0.0, 0.1, 0.01)).y(), 1.0);
  // Without particles the inlet-outlet pressure difference is of the order of the slot's dynamic
  // pressure (the jet's exit static pressure is near ambient): bounded, finite.
  const double dynamic = c.scene.gas.density * g.inletVelocity() * g.inletVelocity();
  EXPECT_LT(std::abs(g.pressureDrop()), dynamic) << g.pressureDrop() << " Pa";
}

TEST(GasProCell, NonFiniteOrOutOfRangeAlphaRefused) {
  GasCase c(quickSliceScene(false));
  std::vector<double> alpha(std::size_t(c.grid.cellCount()), 1.0);
  alpha[123] = std::nan("");
  try {
    c.solver->setGasFraction(alpha);
    FAIL() << "NaN accepted";
  } catch (const RunError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("alpha_G"), std::string::npos) << m;
    EXPECT_NE(m.find("cell 123"), std::string::npos) << m;
    EXPECT_NE(m.find("(0, 1]"), std::string::npos) << m;
  }
  alpha[123] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(c.solver->setGasFraction(alpha), RunError);
  alpha[123] = 0.0;
  EXPECT_THROW(c.solver->setGasFraction(alpha), RunError);
  alpha[123] = 1.0;
  alpha.pop_back();
  EXPECT_THROW(c.solver->setGasFraction(alpha), RunError);
}

TEST(GasProCell, BoxWithoutOutletRefused) {
  Scene s = test::boxScene(Vec3(0.05, 0.05, 0.05), Vec3(0.01, 0.01, 0.01), 0.0);
  s.apparatus.box_outlet_top = false;
  Apparatus a(s.apparatus);
  const CartesianGrid grid = makeGrid(a, s.grid);
  try {
    gas::GasSolver g(s, a, grid);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    ASSERT_FALSE(e.violations().empty());
    EXPECT_EQ(e.violations()[0].pointer, "/apparatus/outlet_top");  // the scene key, not the C++ member
  }
}

}  // namespace
}  // namespace rcfd
