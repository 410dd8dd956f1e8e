// Sliding friction on an incline, rolling on an incline, rolling friction stopping distance.
#include <gtest/gtest.h>

#include "DemTestUtil.hpp"

namespace rcfd {
namespace {

using Eigen::Vector3d;
using namespace demtest;

const QuietLog quiet;
constexpr double kRadius = 0.01;
constexpr double kG = 9.81;

// A sphere resting on the floor of a box (settled under vertical gravity first).
DemSystem restingSphere(const DemMaterial& m, bool lock_rotation) {
  DemSettings s;
  s.time_step = 2e-5;
  s.max_overlap_fraction = 1.0;
  s.rolling_model = m.particle_wall.rolling > 0.0 ? "cdt" : "";
  DemSystem dem(m, DemWalls::box(Vector3d(-1, 0, -1), Vector3d(1, 1, 1)), s);
  dem.addParticle(Vector3d(0, kRadius, 0));
  if (lock_rotation) dem.particles().lockRotation(0);
  dem.run(5000);  // 0.1 s: the small drop onto the floor has died out
  EXPECT_LT(dem.particles().v[0].norm(), 1e-4);
  return dem;
}

// Tilts gravity slowly to theta (the floor becomes an incline; a sudden tilt would overshoot the
// tangential spring and slip), then holds it for t; returns the x displacement and the mean
// acceleration during the hold.
std::pair<double, double> holdOnIncline(DemSystem& dem, double theta_deg, double t) {
  const double th = theta_deg * M_PI / 180.0;
  const int ramp = 200;
  for (int k = 1; k <= ramp; ++k) {
    const double a = th * k / ramp;
    dem.setGravity(Vector3d(kG * std::sin(a), -kG * std::cos(a), 0.0));
    dem.run(static_cast<long>(2.5e-4 / dem.timeStep()));
  }
  const double x0 = dem.particles().x[0].x(), v0 = dem.particles().v[0].x();
  dem.run(static_cast<long>(t / dem.timeStep()));
  return {dem.particles().x[0].x() - x0, (dem.particles().v[0].x() - v0) / t};
}

// Sliding is the only mode when the sphere cannot rotate (a block); a free sphere rolls instead,
// for any angle, so the friction angle is measured with the rotation locked.
TEST(Incline, LockedSphereStartsSlidingAtFrictionAngle) {
  const double mu = 0.24;  // the paper's particle-wall friction
  const DemMaterial m = material(kRadius, 0.9, 0.75, 0.5, mu);
  const double critical = std::atan(mu) * 180.0 / M_PI;
  const double t = 0.2;
  {
    DemSystem dem = restingSphere(m, true);
    const auto [x, a] = holdOnIncline(dem, critical - 0.5, t);
    EXPECT_LT(std::abs(x), 1e-7) << "sticks 0.5 deg below atan(mu)";
  }
  {
    DemSystem dem = restingSphere(m, true);
    const double th = (critical + 0.5) * M_PI / 180.0;
    const auto [x, a] = holdOnIncline(dem, critical + 0.5, t);
    const double expected = kG * (std::sin(th) - mu * std::cos(th));
    EXPECT_GT(x, 0.0) << "slides 0.5 deg above atan(mu)";
    EXPECT_NEAR(a, expected, 0.03 * expected) << "a = g (sin theta - mu cos theta)";
  }
}

TEST(Incline, FreeSphereRollsWithoutSlipping) {
  const DemMaterial m = material(kRadius, 0.9, 0.75, 0.5, 0.24);
  DemSystem dem = restingSphere(m, false);
  const double theta = 10.0, t = 0.2;  // tan(10 deg) < 7/2 mu: rolling without slip
  const auto [x, a] = holdOnIncline(dem, theta, t);
  const double expected = 5.0 / 7.0 * kG * std::sin(theta * M_PI / 180.0);
  EXPECT_NEAR(a, expected, 0.01 * expected) << "a = 5/7 g sin(theta)";
  const auto& p = dem.particles();
  EXPECT_NEAR(p.omega[0].z() * kRadius, -p.v[0].x(), 0.01 * p.v[0].x()) << "v = omega R";
}

// Constant directional torque mu_r m g R against rolling: a = 5/7 mu_r g, s = 7 v0^2 / (10 mu_r g).
TEST(RollingFriction, StopsRollingSphereAtAnalyticDistance) {
  const double mu_r = 0.05, v0 = 0.1;
  const DemMaterial m = material(kRadius, 0.9, 0.75, 0.5, 0.24, 0.06, mu_r);
  DemSystem dem = restingSphere(m, false);
  ASSERT_TRUE(dem.hasRollingModel());
  auto& p = dem.particles();
  p.v[0] = Vector3d(v0, 0, 0);
  p.omega[0] = Vector3d(0, 0, -v0 / kRadius);
  const double x0 = p.x[0].x();
  long k = 0;
  while (p.v[0].x() > 0.0 && k++ < 200000) dem.step();
  const double expected = 7.0 * v0 * v0 / (10.0 * mu_r * kG);
  RecordProperty("distance_over_analytic", std::to_string((p.x[0].x() - x0) / expected));
  EXPECT_NEAR(p.x[0].x() - x0, expected, 0.05 * expected);
}

TEST(RollingFriction, AbsentModelLetsTheSphereRollOn) {
  const DemMaterial m = material(kRadius, 0.9, 0.75, 0.5, 0.24, 0.0, 0.0);
  DemSystem dem = restingSphere(m, false);
  ASSERT_FALSE(dem.hasRollingModel());
  auto& p = dem.particles();
  p.v[0] = Vector3d(0.1, 0, 0);
  p.omega[0] = Vector3d(0, 0, -0.1 / kRadius);
  dem.run(10000);
  EXPECT_NEAR(p.v[0].x(), 0.1, 1e-3);
}

}  // namespace
}  // namespace rcfd
