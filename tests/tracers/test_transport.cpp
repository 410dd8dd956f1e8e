// Transport and walls on analytic fields: exact displacement, exact mirror reflection, no escapes.
#include <gtest/gtest.h>

#include <iostream>

#include "core/Errors.hpp"
#include "../BitIdentical.hpp"
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

/// Velocities a tracer moves with in 16 steps of dt_rec / 4 over frames with u_x = n, on a path
/// 0 1 2 3 | 0 ... (a jump after frame 3).
static std::vector<double> velocitiesBetweenFrames(const std::string& rule) {
  const double dtRec = 0.01, dt = 0.0025;
  Scene s = boxScene({1.0, 1.0, 1.0}, 0.25, 1, dt, {"transport", "walls"});
  s.rcfd.frame_interpolation = rule;
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
  return velocities;
}

TEST(Transport, SmallerDtHoldsEachFrameOverItsIntervalByDefault) {
  const std::vector<double> expected = {0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3};
  const auto held = velocitiesBetweenFrames(Scene{}.rcfd.frame_interpolation);
  for (std::size_t k = 0; k < expected.size(); ++k) EXPECT_NEAR(held[k], expected[k], 1e-9) << k;
}

TEST(Transport, SmallerDtBlendsLinearlyWithinASequenceOnly) {
  // Frames 0..3 blended in quarters, then frame 3 held (jump to 0 next), then frame 0 again.
  const std::vector<double> expected = {0, 0.25, 0.5, 0.75, 1, 1.25, 1.5, 1.75, 2, 2.25, 2.5, 2.75, 3, 3, 3, 3};
  const auto blended = velocitiesBetweenFrames("linear");
  for (std::size_t k = 0; k < expected.size(); ++k) EXPECT_NEAR(blended[k], expected[k], 1e-9) << k;
}

TEST(Transport, TracersCrossAnIntermittentDiluteJetAtTheParticlesSpeed) {
  // A dilute jet rising at U whose parcels sit in every other cell, the other half in the next frame:
  // the empty cells carry no velocity. Completed from their neighbours (VelocityCompletion.hpp), every
  // tracer rises at U as the particles do; interpolated with the empty cells' 0 it would rise at
  // about U / 2, the long spray-zone stays of a dilute jet.
  const double U = 0.5, dt = 0.005;
  Scene s = boxScene({0.02, 0.1, 0.01}, 0.01, 400, dt, {"transport", "walls"}, 0.005);
  const CartesianGrid grid = gridOf(s);
  auto db = database(s, 8, dt, [&](int n, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const bool occupied = (grid.cellIjk(c)[1] + n) % 2 == 0;
      f.alpha_p[std::size_t(c)] = occupied ? 0.01f : 0.0f;
      f.u_p[3 * std::size_t(c) + 1] = occupied ? float(U) : 0.0f;
    }
  });
  const std::int64_t steps = 6;  // 1.5 cm
  TracerSimulation sim(s, db, sequentialPath(8, steps + 2), {1, steps, 0});
  const TracerCloud start = sim.cloud();
  for (std::int64_t k = 0; k < steps; ++k) sim.step();
  const double lift = double(float(U)) * dt * double(steps);
  long counted = 0;
  for (std::size_t i = 0; i < start.size(); ++i) {
    const std::size_t id = std::size_t(sim.cloud().id[i]);
    if (start.y[id] > grid.origin.y() + 0.08) continue;  // clear of the lid
    EXPECT_NEAR(sim.cloud().y[i] - start.y[id], lift, 1e-6) << "tracer " << id;
    ++counted;
  }
  EXPECT_GT(counted, 100);
}

namespace {
/// Share of the particle volume alpha_P V that the tracers hold in the two cell rows on either side of a
/// density step, y in [0.09, 0.11] m, averaged over the last 20 of 60 steps: a steady upward flow whose
/// flux alpha_P u_P is the same everywhere, dense and slow below y = 0.1 m (alpha_P 0.5, 0.1 m/s), dilute
/// and fast above (0.05, 1 m/s). The particles' alpha_P does not change; 1 when the tracers keep it.
double tracerShareAtADensityStep(const std::string& velocityInterpolation) {
  const double dt = 0.005;
  Scene s = boxScene({0.1, 0.2, 0.02}, 0.01, 100000, dt, {"transport", "walls"});
  s.rcfd.velocity_interpolation = velocityInterpolation;
  const CartesianGrid grid = gridOf(s);
  auto db = database(s, 3, dt, [&](int, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const bool dense = grid.cellIjk(c)[1] < 10;
      f.alpha_p[std::size_t(c)] = dense ? 0.5f : 0.05f;
      f.u_p[3 * std::size_t(c) + 1] = dense ? 0.1f : 1.0f;
    }
  });
  const std::int64_t steps = 60;  // the dense side moves 3 cm, the step's cells settle within 2
  TracerSimulation sim(s, db, sequentialPath(3, steps + 2), {1, steps, 0});
  double held = 0.0;
  for (std::int64_t k = 1; k <= steps; ++k) {
    sim.step();
    if (k <= steps - 20) continue;
    for (const double y : sim.cloud().y) held += (y >= 0.09 && y < 0.11) ? 1.0 : 0.0;
  }
  held /= 20.0;
  // Tracers are placed with alpha_P V: a dense cell holds 10 x a dilute one.
  const double rowsShare = (0.5 + 0.05) / (10 * 0.5 + 10 * 0.05);
  return held / (rowsShare * double(s.rcfd.tracers));
}
}  // namespace

// Trilinear velocities accelerate the dense side's tracers toward the step over half a cell, so the
// step's cells hold about three quarters of their particle volume (a dense layer over a dilute fall
// drains: the draft plates' tops, docs/calibration.md); interpolating the flux alpha_P u_P and alpha_P
// alike keeps it.
TEST(Transport, MassWeightedVelocityCarriesTheParticleFluxAcrossADensityStep) {
  const double trilinear = tracerShareAtADensityStep("trilinear");
  const double weighted = tracerShareAtADensityStep("mass_weighted");
  EXPECT_NEAR(weighted, 1.0, 0.03);
  EXPECT_LT(trilinear, 0.85);
  std::cout << "tracers over particle volume at the step: trilinear " << trilinear << ", mass-weighted " << weighted
            << "\n";
}

// The mass-weighted velocity is built per step from the frames alone: bit-identical for 1 and 2 threads
// and across a resume, with the tracer count kept, on the density step with Eq. (10) on top.
TEST(Transport, MassWeightedVelocityIsBitIdenticalForOneAndTwoThreadsAndAcrossAResume) {
  const double dt = 0.005;
  Scene s = boxScene({0.1, 0.2, 0.02}, 0.01, 20000, dt, {"transport", "walls", "tracer_volume_fraction", "fluctuation"});
  s.rcfd.velocity_interpolation = "mass_weighted";
  s.rcfd.d0 = 1e-3;
  const CartesianGrid grid = gridOf(s);
  auto db = database(s, 3, dt, [&](int n, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      const bool dense = ijk[1] < 10 + n;
      f.alpha_p[std::size_t(c)] = dense ? 0.5f : 0.05f;
      f.u_p[3 * std::size_t(c)] = 0.05f * float(ijk[0] % 3 - 1);
      f.u_p[3 * std::size_t(c) + 1] = dense ? 0.1f : 1.0f;
    }
  });
  const auto two = runSteps(s, db, 7, 40, 2, -1, "mass-weighted-checkpoint.h5");
  const auto one = runSteps(s, db, 7, 40, 1, -1, "mass-weighted-checkpoint.h5");
  const auto resumed = runSteps(s, db, 7, 40, 2, 17, "mass-weighted-checkpoint.h5");
  ASSERT_EQ(two->cloud().size(), std::size_t(20000));
  EXPECT_TRUE(bitIdentical(two->cloud().x, one->cloud().x));
  EXPECT_TRUE(bitIdentical(two->cloud().y, one->cloud().y));
  EXPECT_TRUE(bitIdentical(two->cloud().y, resumed->cloud().y));
  EXPECT_TRUE(bitIdentical(two->cloud().z, resumed->cloud().z));
}
