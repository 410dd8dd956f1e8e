// The coupled CFD-DEM gives bit-identical parcels for one and two OpenMP threads (the DEM's own
// guarantee kept through the fluid forces, the mapping and the exchange).

#include <gtest/gtest.h>
#include <omp.h>

#include "CouplingTestSupport.hpp"

namespace rcfd {
namespace {

DemParticles runWithThreads(int threads) {
  const int before = omp_get_max_threads();
  omp_set_num_threads(threads);
  Scene s = test::quickSlice();
  s.dem.time_step = 2.5e-5;
  s.dem.coupling_interval = 25;
  s.gas.max_time_step = 2.5e-4;
  CfdDemSimulation sim(s, 1);
  // 5000 parcels (above the parallel thresholds of the DEM and the mapping) over the inlet.
  test::scatterParcels(sim.dem(), sim.apparatus(), 5000, sim.dem().material().particle_radius, 21, 0.2, 0.5);
  for (int k = 0; k < 8; ++k) sim.step(sim.demStep() + 25);
  omp_set_num_threads(before);
  return sim.dem().particles();
}

TEST(CfdDemDeterminism, BitIdenticalForOneAndTwoThreads) {
  const DemParticles a = runWithThreads(1), b = runWithThreads(2);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.v, b.v);
  EXPECT_EQ(a.fluid_force, b.fluid_force);
}

}  // namespace
}  // namespace rcfd
