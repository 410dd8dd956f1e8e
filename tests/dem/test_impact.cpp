// Normal impacts against the analytic Hertz solution: restitution and contact duration.
#include <gtest/gtest.h>

#include "DemTestUtil.hpp"

namespace rcfd {
namespace {

using Eigen::Vector3d;
using namespace demtest;

const QuietLog quiet;
constexpr double kRadius = 0.01;
constexpr double kSpeed = 1.0;

// A sphere hits the floor of a large box without gravity; returns (v_out / v_in, contact time).
std::pair<double, double> wallImpact(const DemMaterial& m, double dt) {
  DemSettings s;
  s.time_step = dt;
  s.gravity.setZero();
  s.max_overlap_fraction = 1.0;
  DemSystem dem(m, DemWalls::box(Vector3d(-1, 0, -1), Vector3d(1, 1, 1)), s);
  dem.addParticle(Vector3d(0, kRadius * 1.001, 0), Vector3d(0, -kSpeed, 0));
  long in_contact = 0;
  for (long k = 0; k < 100000; ++k) {
    dem.step();
    if (dem.lastStats().wall_contacts > 0) ++in_contact;
    else if (in_contact > 0) break;
  }
  return {dem.particles().v[0].y() / kSpeed, in_contact * dt};
}

// Two equal spheres collide head-on at relative speed kSpeed.
std::pair<double, double> pairImpact(const DemMaterial& m, double dt) {
  DemSettings s;
  s.time_step = dt;
  s.gravity.setZero();
  s.max_overlap_fraction = 1.0;
  DemSystem dem(m, DemWalls(), s);
  dem.addParticle(Vector3d(-kRadius * 1.001, 0, 0), Vector3d(0.5 * kSpeed, 0, 0));
  dem.addParticle(Vector3d(kRadius * 1.001, 0, 0), Vector3d(-0.5 * kSpeed, 0, 0));
  long in_contact = 0;
  for (long k = 0; k < 100000; ++k) {
    dem.step();
    if (dem.lastStats().contacts > 0) ++in_contact;
    else if (in_contact > 0) break;
  }
  const auto& v = dem.particles().v;
  EXPECT_NEAR(v[0].x() + v[1].x(), 0.0, 1e-12) << "momentum";
  return {(v[1].x() - v[0].x()) / kSpeed, in_contact * dt};
}

class Restitution : public ::testing::TestWithParam<double> {};

TEST_P(Restitution, SphereOnWallRecoversE) {
  const double e = GetParam();
  const DemMaterial m = material(kRadius, 0.9, e);
  const double tc = hertzDuration(sphereMass(m), kRadius, m.particle_wall.y_eff, kSpeed);
  const auto [ratio, duration] = wallImpact(m, tc / 400);
  RecordProperty("restitution", std::to_string(ratio));
  EXPECT_NEAR(ratio, e, 0.01 * e);
}

TEST_P(Restitution, SphereOnSphereRecoversE) {
  const double e = GetParam();
  const DemMaterial m = material(kRadius, e, 0.75);
  const double tc = hertzDuration(0.5 * sphereMass(m), 0.5 * kRadius, m.particle_particle.y_eff, kSpeed);
  const auto [ratio, duration] = pairImpact(m, tc / 400);
  RecordProperty("restitution", std::to_string(ratio));
  EXPECT_NEAR(ratio, e, 0.01 * e);
}

INSTANTIATE_TEST_SUITE_P(Dem, Restitution, ::testing::Values(0.5, 0.75, 0.9, 0.95));

TEST(HertzContact, DurationOnWallMatchesAnalytic) {
  const DemMaterial m = material(kRadius, 1.0, 1.0);
  const double tc = hertzDuration(sphereMass(m), kRadius, m.particle_wall.y_eff, kSpeed);
  const auto [ratio, duration] = wallImpact(m, tc / 500);
  RecordProperty("duration_over_analytic", std::to_string(duration / tc));
  EXPECT_NEAR(duration, tc, 0.02 * tc);
  EXPECT_NEAR(ratio, 1.0, 1e-3) << "undamped impact is elastic";
}

TEST(HertzContact, DurationBetweenSpheresMatchesAnalytic) {
  const DemMaterial m = material(kRadius, 1.0, 1.0);
  const double tc = hertzDuration(0.5 * sphereMass(m), 0.5 * kRadius, m.particle_particle.y_eff, kSpeed);
  const auto [ratio, duration] = pairImpact(m, tc / 500);
  RecordProperty("duration_over_analytic", std::to_string(duration / tc));
  EXPECT_NEAR(duration, tc, 0.02 * tc);
}

TEST(HertzContact, RestitutionIndependentOfSpeedAndSize) {
  // The coarse-graining argument (docs/dem.md): same material, 3x the radius and 5x the speed.
  const DemMaterial m = material(3 * kRadius, 0.9, 0.75);
  DemSettings s;
  s.time_step = 2e-6;
  s.gravity.setZero();
  s.max_overlap_fraction = 1.0;
  DemSystem dem(m, DemWalls::box(Vector3d(-1, 0, -1), Vector3d(1, 1, 1)), s);
  dem.addParticle(Vector3d(0, 3 * kRadius * 1.001, 0), Vector3d(0, -5.0, 0));
  for (long k = 0; k < 20000 && (dem.particles().v[0].y() < 0.0 || dem.lastStats().wall_contacts > 0); ++k)
    dem.step();
  EXPECT_NEAR(dem.particles().v[0].y() / 5.0, 0.75, 0.0075);
}

}  // namespace
}  // namespace rcfd
