// The coupling step: a whole number of DEM steps, at most coupling_interval, never past the caller's
// target, within the gas CFL limit; a non-finite state stops the run with a RunError saying where.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "CouplingTestSupport.hpp"
#include "core/Errors.hpp"

namespace rcfd {
namespace {

Scene slice() {
  Scene s = test::quickSlice();
  s.dem.time_step = 2.5e-5;
  s.dem.coupling_interval = 25;
  s.gas.max_time_step = 2.5e-4;
  return s;
}

TEST(CouplingStep, WholeDemStepsWithinIntervalTargetAndCfl) {
  const Scene s = slice();
  CfdDemSimulation sim(s, 1);
  test::scatterParcels(sim.dem(), sim.apparatus(), 500, sim.dem().material().particle_radius, 4, 0.15);
  const double dtDem = sim.demTimeStep();
  for (int n = 0; n < 20; ++n) {
    const std::int64_t before = sim.demStep(), target = before + 7 + n % 5 * 13;  // odd targets
    const auto& st = sim.step(target);
    EXPECT_GE(st.demSteps, 1);
    EXPECT_LE(st.demSteps, s.dem.coupling_interval);
    EXPECT_LE(sim.demStep(), target);
    EXPECT_EQ(sim.demStep(), before + st.demSteps);
    EXPECT_DOUBLE_EQ(st.dt, st.demSteps * dtDem);
    EXPECT_NEAR(sim.gasSolver()->lastStep().dt, st.dt, 1e-15);  // one gas step of exactly k dt_DEM
    // The CFL limit holds for the velocities the step starts from; after it they have moved a little.
    EXPECT_LE(st.courant, 1.1 * s.gas.cfl);
    EXPECT_DOUBLE_EQ(sim.time(), double(sim.demStep()) * dtDem);
  }
  EXPECT_THROW(sim.step(sim.demStep()), RunError);  // no step backwards or of zero length
}

TEST(CouplingStep, NonFiniteParcelStopsWithItsIdentity) {
  const Scene s = slice();
  CfdDemSimulation sim(s, 1);
  test::scatterParcels(sim.dem(), sim.apparatus(), 50, sim.dem().material().particle_radius, 5, 0.15);
  sim.step(sim.demStep() + 25);
  sim.dem().particles().v[7] = Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0, 0);
  try {
    sim.step(sim.demStep() + 25);
    FAIL() << "no RunError";
  } catch (const RunError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("parcel"), std::string::npos) << what;
    EXPECT_NE(what.find("t = "), std::string::npos) << what;
  }
}

TEST(CouplingStep, FlowFactorOutsideZeroOneRefused) {
  const Scene s = slice();
  CfdDemSimulation sim(s, 1);
  EXPECT_THROW(sim.setFlowFactor(1.5), RunError);
  EXPECT_THROW(sim.setFlowFactor(-0.1), RunError);
  sim.setFlowFactor(0.5);
  EXPECT_NEAR(sim.gasSolver()->inletVelocity(), 0.5 * s.process.gas_flow_rate / (0.02 * 0.02), 1e-9);
}

}  // namespace
}  // namespace rcfd
