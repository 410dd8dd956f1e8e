// Checkpoints: save -> load -> continue equals continuing. DEM-only bit-identical (contact history
// kept); with gas within the pressure tolerance (the pressure preconditioner is rebuilt after a load).

#include <gtest/gtest.h>

#include <filesystem>

#include "CouplingTestSupport.hpp"
#include "core/Hdf5.hpp"

namespace rcfd {
namespace {

Scene smallBed(bool gas) {
  Scene s = test::couplingBox(Vec3(0.03, 0.09, 0.03), 0.005, 0.6 * 0.03 * 0.03);
  s.dem.coarse_graining = 2.0;
  s.dem.time_step = 2e-5;
  s.dem.coupling_interval = 10;
  s.dem.settle_time = 0.05;
  s.gas.max_time_step = 2e-4;
  s.process.bed_mass = 0.008;
  s.effects = gas ? std::vector<std::string>{"gas", "drag", "smoothing", "rolling_friction"}
                  : std::vector<std::string>{"rolling_friction"};
  return s;
}

double maxDifference(const DemParticles& a, const DemParticles& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max({m, (a.x[i] - b.x[i]).norm(), (a.v[i] - b.v[i]).norm()});
  return m;
}

void saveLoadContinue(bool withGas) {
  const Scene s = smallBed(withGas);
  gas::GasOptions go;
  go.boxBottomInlet = true;
  CfdDemSimulation a(s, 3, go);
  a.fillAndSettle();
  for (int k = 0; k < 20; ++k) a.step(a.demStep() + 10);
  const std::string path = (std::filesystem::temp_directory_path() / ("rcfd-coupling-state-" +
                            std::to_string(::getpid()) + (withGas ? "-gas" : "-dem") + ".h5")).string();
  {
    h5::File f(path, h5::File::Mode::Create);
    a.saveState(f, "/state");
  }
  CfdDemSimulation b(s, 3, go);
  {
    h5::File f(path, h5::File::Mode::ReadOnly);
    b.loadState(f, "/state");
  }
  std::filesystem::remove(path);
  EXPECT_EQ(b.demStep(), a.demStep());
  EXPECT_EQ(b.particleFraction(), a.particleFraction());
  for (int k = 0; k < 30; ++k) {
    a.step(a.demStep() + 10);
    b.step(b.demStep() + 10);
  }
  ASSERT_EQ(a.dem().particles().size(), b.dem().particles().size());
  EXPECT_EQ(a.dem().particles().id, b.dem().particles().id);
  const double diff = maxDifference(a.dem().particles(), b.dem().particles());
  if (withGas) {
    EXPECT_LT(diff, 1e-9);
    EXPECT_NEAR(a.pressureDrop(), b.pressureDrop(), 1e-6 * std::abs(a.pressureDrop()));
  } else {
    EXPECT_EQ(diff, 0.0);
    EXPECT_EQ(a.dem().particles().x, b.dem().particles().x);
  }
}

TEST(CfdDemState, SaveLoadContinueIsBitIdenticalWithoutGas) { saveLoadContinue(false); }
TEST(CfdDemState, SaveLoadContinueAgreesWithGasToThePressureTolerance) { saveLoadContinue(true); }

}  // namespace
}  // namespace rcfd
