// Transport and walls on analytic fields: exact displacement, exact mirror reflection, no escapes.
#include <gtest/gtest.h>

#include "core/Errors.hpp"
#include "TracerTestSupport.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {
/// One step of a kinematic tracer pushed toward the wall x = hi: the displacement is mirrored at the
/// wall (the tracer has no velocity of its own to reverse, so it stays within one step of the wall).
double mirrorStep(double x, double disp, double hi) {
  const double end = x + disp;
  return end > hi ? 2.0 * hi - end : end;
}
}  // namespace

TEST(Transport, UniformFlowDisplacementIsExactAndWallsMirror) {
  const double U = 0.37, dt = 0.01;
  Scene s = boxScene({0.1, 0.1, 0.1}, 0.01, 200, dt, {"transport", "walls"});
  auto db = database(s, 10, dt, [&](int, double, FieldFrame& f) {
    for (std::size_t c = 0; c < f.alpha_p.size(); ++c) {
      f.alpha_p[c] = 0.3f;
      f.u_p[3 * c] = float(U);
    }
  });
  const std::int64_t steps = 300;  // 1.11 m: every tracer reaches the wall x = 0.05 early
  TracerSimulation sim(s, db, sequentialPath(10, steps + 2), {1, steps, 0});
  const TracerCloud start = sim.cloud();
  // Hit points lie about 2 boundaryTolerance() (1e-9 of the apparatus size) inside the wall.
  const double kReflectionTolerance = 3e-9 * 0.1;
  std::vector<double> expected = start.x;
  std::int64_t reflections = 0;
  for (std::int64_t k = 1; k <= steps; ++k) {
    sim.step();
    for (std::size_t i = 0; i < start.size(); ++i) {
      const double before = expected[i];
      expected[i] = mirrorStep(before, double(float(U)) * dt, 0.05);
      reflections += expected[i] < before;
    }
    for (std::size_t i = 0; i < start.size(); ++i) {
      const std::size_t id = std::size_t(sim.cloud().id[i]);  // re-sorted by cell every 100 steps
      ASSERT_NEAR(sim.cloud().x[i], expected[id], kReflectionTolerance) << "tracer " << id << " step " << k;
      ASSERT_EQ(sim.cloud().y[i], start.y[id]);
      ASSERT_EQ(sim.cloud().z[i], start.z[id]);
    }
  }
  EXPECT_GT(reflections, 200);
}

TEST(Transport, DiagonalFlowNeverLeavesTheBox) {
  const double dt = 0.005;
  Scene s = boxScene({0.08, 0.12, 0.05}, 0.01, 500, dt, {"transport", "walls"});
  auto db = database(s, 8, dt, [&](int n, double, FieldFrame& f) {
    for (std::size_t c = 0; c < f.alpha_p.size(); ++c) {
      f.alpha_p[c] = 0.2f;
      f.u_p[3 * c] = float(3.0 + n);      // up to 10 m/s: sub-steps and several reflections per step
      f.u_p[3 * c + 1] = float(-7.0 + n);
      f.u_p[3 * c + 2] = 5.0f;
    }
  });
  const std::int64_t steps = 400;
  TracerSimulation sim(s, db, sequentialPath(8, steps + 2), {3, steps, 0});
  Apparatus box(s.apparatus);
  for (std::int64_t k = 0; k < steps; ++k) {
    sim.step();
    for (std::size_t i = 0; i < sim.cloud().size(); ++i) {
      ASSERT_GE(box.signedDistance(sim.cloud().position(i)), -1e-12) << "tracer " << i << " step " << k;
    }
  }
  EXPECT_GT(sim.motionStatistics().substeps, 0);
}

TEST(Transport, DtMustDivideDtRec) {
  Scene s = boxScene({0.1, 0.1, 0.1}, 0.02, 10, 0.003, {"transport", "walls"});
  auto db = database(s, 4, 0.005, [](int, double, FieldFrame& f) {
    std::fill(f.alpha_p.begin(), f.alpha_p.end(), 0.1f);
  });
  try {
    TracerSimulation sim(s, db, sequentialPath(4, 100), {1, 10, 0});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.violations().at(0).pointer, "/rcfd/dt");
  }
}

TEST(Transport, SmallerDtInterpolatesWithinASequenceOnly) {
  // Frame n has u_x = n; dt = dt_rec / 4, so steps inside a sequence see blended velocities and the
  // step just before a jump (frame 3 -> 0) sees frame 3 only.
  const double dtRec = 0.01, dt = 0.0025;
  Scene s = boxScene({1.0, 1.0, 1.0}, 0.25, 1, dt, {"transport", "walls"});
  auto db = database(s, 4, dtRec, [](int n, double, FieldFrame& f) {
    for (std::size_t c = 0; c < f.alpha_p.size(); ++c) {
      f.alpha_p[c] = 0.3f;
      f.u_p[3 * c] = float(n);
    }
  });
  TracerSimulation sim(s, db, sequentialPath(4, 20), {1, 16, 0});
  std::vector<double> velocities;
  for (int k = 0; k < 16; ++k) {
    const double x0 = sim.cloud().x[0];
    sim.step();
    velocities.push_back((sim.cloud().x[0] - x0) / dt);
  }
  // Frames 0..3 blended in quarters, then frame 3 held (jump to 0 next), then frame 0 again.
  const std::vector<double> expected = {0, 0.25, 0.5, 0.75, 1, 1.25, 1.5, 1.75, 2, 2.25, 2.5, 2.75, 3, 3, 3, 3};
  for (std::size_t k = 0; k < expected.size(); ++k) EXPECT_NEAR(velocities[k], expected[k], 1e-9) << k;
}
