// Energy conservation without damping and friction; the Rayleigh time-step check.
#include <gtest/gtest.h>

#include <random>

#include "DemTestUtil.hpp"
#include "core/Errors.hpp"

namespace rcfd {
namespace {

using Eigen::Vector3d;
using namespace demtest;

const QuietLog quiet;

TEST(Energy, ConservedWithoutDampingOrFriction) {
  const double r = 0.01;
  const DemMaterial m = material(r, 1.0, 1.0);  // e = 1, mu = 0, no rolling friction
  DemSettings s;
  s.time_step = 4e-6;
  s.max_overlap_fraction = 1.0;
  DemSystem dem(m, DemWalls::box(Vector3d(-0.05, 0, -0.05), Vector3d(0.05, 0.1, 0.05)), s);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 6; ++i)
    dem.addParticle(Vector3d(-0.03 + 0.03 * (i % 3), 0.03 + 0.03 * (i / 3), 0.02 * u(rng)),
                    Vector3d(u(rng), u(rng), u(rng)));
  const double e0 = dem.totalEnergy();
  // Energy available for motion: kinetic + potential above the resting height.
  const double scale = e0 + 6 * sphereMass(m) * 9.81 * (-r);
  double worst = 0.0;
  long contacts = 0;
  for (long k = 0; k < 100000; ++k) {
    dem.step();
    contacts += dem.lastStats().contacts + dem.lastStats().wall_contacts;
    if (k % 10 == 0) worst = std::max(worst, std::abs(dem.totalEnergy() - e0));
  }
  EXPECT_GT(contacts, 1000) << "the particles must actually collide";
  RecordProperty("relative_energy_error", std::to_string(worst / scale));
  EXPECT_LT(worst / scale, 1e-4);
}

TEST(TimeStep, RefusesAboveRayleighFraction) {
  const DemMaterial m = material(0.9e-3, 0.9, 0.75, 0.5, 0.24, 0.06, 0.05, 5e6, 1040.0);
  const double t_r = m.rayleighTime();
  // pi R sqrt(rho/G) / (0.1631 nu + 0.8766) with G = Y / 2.5
  EXPECT_NEAR(t_r, M_PI * 0.9e-3 * std::sqrt(1040.0 / 2e6) / (0.1631 * 0.25 + 0.8766), 1e-15);
  DemSettings s;
  s.max_rayleigh_fraction = 0.3;
  s.time_step = 0.31 * t_r;
  try {
    DemSystem dem(m, DemWalls(), s);
    FAIL() << "a time step of 0.31 t_R must be refused";
  } catch (const InputError& e) {
    ASSERT_EQ(e.violations().size(), 1u);
    EXPECT_EQ(e.violations()[0].pointer, "/dem/time_step");
    EXPECT_NE(e.violations()[0].message.find("allows at most"), std::string::npos)
        << e.violations()[0].message;
  }
  s.time_step = 0.29 * t_r;
  DemSystem ok(m, DemWalls(), s);
  EXPECT_NEAR(ok.rayleighFraction(), 0.29, 1e-12);
}

TEST(TimeStep, CoarseGrainingScalesTheRayleighTime) {
  Scene scene;
  scene.dem.coarse_graining = 3.0;
  const DemMaterial cg3 = DemMaterial::fromScene(scene);
  scene.dem.coarse_graining = 1.0;
  const DemMaterial cg1 = DemMaterial::fromScene(scene);
  EXPECT_NEAR(cg3.particle_radius, 3 * cg1.particle_radius, 1e-15);
  EXPECT_NEAR(cg3.rayleighTime(), 3 * cg1.rayleighTime(), 1e-15);
  EXPECT_EQ(cg3.particle_wall.restitution, cg1.particle_wall.restitution);
}

TEST(TimeStep, WarnsOnceWhenOverlapExceedsLimit) {
  const DemMaterial m = material(0.01, 0.9, 0.75);
  DemSettings s;
  s.time_step = 1e-5;
  s.gravity.setZero();
  s.max_overlap_fraction = 0.003;
  DemSystem dem(m, DemWalls::box(Vector3d(-1, 0, -1), Vector3d(1, 1, 1)), s);
  dem.addParticle(Vector3d(0, 0.01, 0), Vector3d(0, -2, 0));
  dem.run(1000);
  EXPECT_GT(dem.maxOverlapFractionSeen(), 0.003);
}

}  // namespace
}  // namespace rcfd

namespace rcfd {
namespace {

TEST(Effects, RollingFrictionOnlyWhenTheSceneAsksForIt) {
  Scene scene;
  scene.dem.time_step = 1e-6;
  scene.effects = {"walls"};
  DemSettings without = DemSystem::settingsFromScene(scene);
  EXPECT_TRUE(without.rolling_model.empty());
  DemSystem a(DemMaterial::fromScene(scene), DemWalls(), without);
  EXPECT_FALSE(a.hasRollingModel()) << "not asked for: not constructed";
  scene.effects.push_back("rolling_friction");
  DemSettings with = DemSystem::settingsFromScene(scene);
  EXPECT_EQ(with.rolling_model, "cdt");
  DemSystem b(DemMaterial::fromScene(scene), DemWalls(), with);
  EXPECT_TRUE(b.hasRollingModel());
  EXPECT_TRUE(ContactModelRegistry::contains("hertz_mindlin"));
  EXPECT_TRUE(RollingModelRegistry::contains("cdt"));
}

}  // namespace
}  // namespace rcfd
