// The tracer integrator (rcfd.integrator) on solid-body rotation, where the trilinear interpolant of
// the field is the linear field itself: the midpoint rule keeps tracers on their circles where Euler
// spirals outward, and the motion kernel's float lanes (u_P^rec sampled at float grid coordinates)
// follow a double-precision midpoint map of the exact field to far below a micrometre.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>

#include "TracerTestSupport.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {

constexpr double kDt = 0.005;                                    // [s]
constexpr double kOmega = 2.0 * std::numbers::pi / (100 * kDt);  // one revolution in 100 steps [rad/s]
constexpr double kCentreX = 0.0, kCentreY = 0.1;                 // the box spans x in [-0.1, 0.1], y in [0, 0.2]

/// u = omega e_z x (p - centre): linear, so trilinear interpolation reproduces it inside the centres.
Eigen::Vector3d rotation(const Eigen::Vector3d& p) {
  return {-kOmega * (p.y() - kCentreY), kOmega * (p.x() - kCentreX), 0.0};
}

struct RotationCase {
  Scene scene;
  std::shared_ptr<FieldDatabase> db;
  explicit RotationCase(const std::string& integrator) {
    scene = boxScene({0.2, 0.2, 0.04}, 0.01, 400, kDt, {"transport", "walls"});
    scene.rcfd.integrator = integrator;
    const CartesianGrid grid = gridOf(scene);
    db = database(scene, 3, kDt, [grid](int, double, FieldFrame& f) {
      for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
        const auto ijk = grid.cellIjk(c);
        const Eigen::Vector3d u = rotation(grid.cellCenter(ijk[0], ijk[1], ijk[2]));
        f.alpha_p[std::size_t(c)] = 0.3f;
        for (int d = 0; d < 3; ++d) f.u_p[3 * std::size_t(c) + std::size_t(d)] = float(u[d]);
      }
    });
  }
};

double radius(const Eigen::Vector3d& p) { return std::hypot(p.x() - kCentreX, p.y() - kCentreY); }

/// Tracers (by id) whose circle stays inside the outermost cell centres, where the field is exactly linear.
std::vector<std::size_t> tracersOnInnerCircles(const TracerCloud& cloud) {
  std::vector<std::size_t> ids;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double r = radius(cloud.position(i));
    if (r > 0.01 && r < 0.07) ids.push_back(std::size_t(cloud.id[i]));
  }
  return ids;
}

Eigen::Vector3d positionOf(const TracerCloud& cloud, std::size_t id) {
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (std::size_t(cloud.id[i]) == id) return cloud.position(i);
  }
  return Eigen::Vector3d::Constant(std::nan(""));
}

}  // namespace

TEST(Integrator, MidpointKeepsSolidRotationOnItsCirclesWhereEulerSpiralsOut) {
  const std::int64_t steps = 100;  // one revolution: Euler's radius grows by (1 + (omega dt)^2)^50 = 1.22
  for (const std::string integrator : {"midpoint", "euler"}) {
    RotationCase c(integrator);
    TracerSimulation sim(c.scene, c.db, sequentialPath(3, steps + 2), {1, steps, 0});
    const TracerCloud start = sim.cloud();
    const auto ids = tracersOnInnerCircles(start);
    ASSERT_GT(ids.size(), 50u);
    for (std::int64_t k = 0; k < steps; ++k) sim.step();
    double smallest = 1e300, largest = 0.0;
    for (const std::size_t id : ids) {
      const double growth = radius(positionOf(sim.cloud(), id)) / radius(positionOf(start, id));
      smallest = std::min(smallest, growth), largest = std::max(largest, growth);
    }
    if (integrator == "midpoint") {
      // (1 + (omega dt)^4 / 4)^50 - 1 = 1.9e-4 on the exact field
      EXPECT_GT(smallest, 1.0);
      EXPECT_LT(largest, 1.0 + 3e-4) << integrator;
    } else {
      EXPECT_NEAR(smallest, std::pow(1.0 + std::pow(kOmega * kDt, 2), 50), 1e-3) << integrator;
      EXPECT_NEAR(largest, smallest, 1e-3) << integrator;
    }
  }
}

TEST(Integrator, FloatLanesFollowTheDoublePrecisionMidpointMap) {
  const std::int64_t steps = 1000;  // ten revolutions, 3 mm per step at r = 0.05 m
  RotationCase c("midpoint");
  TracerSimulation sim(c.scene, c.db, sequentialPath(3, steps + 2), {1, steps, 0});
  const TracerCloud start = sim.cloud();
  const auto ids = tracersOnInnerCircles(start);
  std::vector<Eigen::Vector3d> reference;
  for (const std::size_t id : ids) reference.push_back(positionOf(start, id));
  for (std::int64_t k = 0; k < steps; ++k) {
    sim.step();
    for (auto& p : reference) p += kDt * rotation(p + 0.5 * kDt * rotation(p));  // the midpoint rule in double
  }
  double worst = 0.0;
  for (std::size_t j = 0; j < ids.size(); ++j) {
    worst = std::max(worst, (positionOf(sim.cloud(), ids[j]) - reference[j]).norm());
  }
  // Float field values (7 digits) and float grid coordinates: 3 m travelled, a few 1e-8 m per step at most.
  EXPECT_LT(worst, 1e-6) << "metres after " << steps << " steps";
  std::cout << "largest distance from the double-precision midpoint map: " << worst << " m\n";
}
