// velocity_streams, the two-stream tracer velocity model, and the comparison of spray-zone stays at a
// common resolution: on a database written from an analytic particle motion whose stays are known
// exactly (balls bouncing on the floor), the streams give the particles' stays and crossing rate where
// the mean velocity (zero everywhere) gives none; alpha_P^rec and the tracer count are kept; results are
// bit-identical for 1 and 2 threads and across a resume; a scene without the effect runs as before and
// allocates nothing for it.
#include <gtest/gtest.h>

#include "../BitIdentical.hpp"
#include <omp.h>

#include <cmath>
#include <cstring>

#include <nlohmann/json.hpp>

#include "analysis/StayComparison.hpp"
#include "tracers/CounterRng.hpp"
#include "core/Errors.hpp"
#include "geometry/SprayZone.hpp"
#include "TracerTestSupport.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {

constexpr double kG = 9.81;

/// Balls bouncing elastically on the floor y = 0 of a box, launched at V0: at height y < h = V0^2 / 2g
/// half the balls rise and half fall, both at v(y) = sqrt(V0^2 - 2 g y), so the mean velocity is zero
/// everywhere and the density is proportional to 1 / v. Cells hold exact cell averages: alpha_P over
/// the cell, and the stream velocity that carries the cell's flux, dy / int(1/v) dy. Each ball crosses
/// a layer [a, b] below h twice per flight of 2 V0 / g, each time in (v(a) - v(b)) / g.
struct BouncingBalls {
  double v0 = 2.215;       ///< launch speed [m/s] (apex 0.25 m)
  double alphaMean = 0.05; ///< alpha_P averaged over the layer below the apex [-]

  double apex() const { return v0 * v0 / (2.0 * kG); }
  double speed(double y) const { return std::sqrt(std::max(0.0, v0 * v0 - 2.0 * kG * y)); }
  /// int_y0^y1 dy / v(y), clipped at the apex.
  double timeThrough(double y0, double y1) const {
    y0 = std::min(y0, apex()), y1 = std::min(y1, apex());
    return (speed(y0) - speed(y1)) / kG;
  }
  double stay(double a, double b) const { return timeThrough(a, b); }
  double crossingRate() const { return 2.0 / (2.0 * v0 / kG); }  // two stays per flight

  /// The frame of a grid: stationary.
  void fill(const CartesianGrid& grid, FieldFrame& f) const {
    const std::size_t cells = std::size_t(grid.cellCount());
    zeroVelocitySpread(f, cells);
    // alpha proportional to the time spent per height, normalised over the layer below the apex.
    const double norm = alphaMean * apex() / timeThrough(0.0, apex());
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      const double y0 = grid.origin.y() + grid.spacing.y() * ijk[1], y1 = y0 + grid.spacing.y();
      const double t = timeThrough(y0, y1);
      if (!(t > 0.0)) continue;
      const double v = (std::min(y1, apex()) - y0) / t;  // flux-carrying stream speed of the cell
      const std::size_t i = std::size_t(c);
      f.alpha_p[i] = float(norm * t / (y1 - y0));
      f.up_fraction[i] = 0.5f;
      f.u_p_up[3 * i + 1] = float(v);
      f.u_p_down[3 * i + 1] = float(-v);
      f.u_p_variance[3 * i + 1] = float(v * v);
    }
  }
};

Scene bouncingScene(long tracers, std::vector<std::string> effects) {
  Scene s = boxScene({0.05, 0.4, 0.01}, 0.01, tracers, 0.005, std::move(effects), 0.05 * 0.25 / 0.4);
  // A layer across the whole box: the zone's cone has its apex far below and a 1 degree half-angle.
  s.spray.spray_zone.apex = Vec3(0.0, -10.0, 0.005);
  s.spray.spray_zone.half_angle_deg = 1.0;
  s.spray.spray_zone.y_min = 0.05;
  s.spray.spray_zone.y_max = 0.15;
  return s;
}

std::shared_ptr<FieldDatabase> bouncingDatabase(const Scene& s, const BouncingBalls& balls, int frames = 20) {
  const CartesianGrid grid = gridOf(s);
  return database(s, frames, s.rcfd.dt, [&](int, double, FieldFrame& f) { balls.fill(grid, f); });
}

struct Outcome {
  nlohmann::json summary;
  std::vector<std::int64_t> stayCounts;
  std::vector<float> alphaTracers, alphaRecurrence;  ///< time averages per cell (field_average)
  TracerCloud cloud;
};

Outcome run(const Scene& s, std::shared_ptr<FieldDatabase> db, std::int64_t steps, std::int64_t discard,
            int threads = 2, std::int64_t checkpointAt = -1) {
  omp_set_num_threads(threads);
  const RecurrencePath path = sequentialPath(db->frameCount(), steps + 2);
  const TracerRunSettings settings{7, steps, discard, true, 7};
  auto sim = std::make_unique<TracerSimulation>(s, db, path, settings);
  for (std::int64_t k = 0; k < steps; ++k) {
    if (k == checkpointAt) {
      const std::string checkpoint = tempPath("streams-checkpoint.h5");
      sim->saveCheckpoint(checkpoint);
      sim = std::make_unique<TracerSimulation>(s, db, path, settings);
      sim->loadCheckpoint(checkpoint);
    }
    sim->step();
  }
  Outcome o;
  h5::File out(tempPath("streams-result.h5"), h5::File::Mode::Create);
  sim->writeResults(out, o.summary);
  if (out.exists("/residence_time/duration_steps_counts")) o.stayCounts = out.readInt64s("/residence_time/duration_steps_counts");
  if (out.exists("/field_average/alpha_p_tracers")) {
    o.alphaTracers = out.readFloats("/field_average/alpha_p_tracers");
    o.alphaRecurrence = out.readFloats("/field_average/alpha_p_recurrence");
  }
  o.cloud = sim->cloud();
  omp_set_num_threads(2);
  return o;
}

const std::vector<std::string> kStreamEffects = {"transport", "walls", "tracer_volume_fraction", "velocity_streams",
                                                 "residence_time", "field_average"};

}  // namespace

TEST(VelocityStreams, BouncingBallsCrossTheZoneAsTheParticlesDoWhereTheMeanVelocityStandsStill) {
  const BouncingBalls balls;
  const long tracers = 4000;
  const std::int64_t steps = 1200, discard = 200;  // 6 s, 1 s discarded: 11 flights
  const double dt = 0.005, period = double(steps - discard) * dt;
  const double exactStay = balls.stay(0.05, 0.15);
  ASSERT_NEAR(exactStay, 0.0592, 1e-3);
  // The reference: what the balls do over the same period, one stay per pass.
  const double passes = balls.crossingRate() * period * tracers;
  const std::vector<double> reference(std::size_t(passes), exactStay);

  Scene s = bouncingScene(tracers, kStreamEffects);
  auto db = bouncingDatabase(s, balls);
  const Outcome streams = run(s, db, steps, discard);
  const auto withStreams = analysis::compareStays(streams.stayCounts, dt, tracers, period, reference, tracers, period);
  EXPECT_LT(std::abs(withStreams.meanError()), 0.10) << withStreams.toJson().dump(1);
  EXPECT_LT(std::abs(withStreams.crossingRateError()), 0.10) << withStreams.toJson().dump(1);
  EXPECT_LE(withStreams.ksDistance, 0.10) << withStreams.toJson().dump(1);
  // The bed's shape: the streams add little over-packing to the counting noise of 4000 tracers.
  EXPECT_LT(streams.summary["field_average"]["rms_over_floor"].get<double>(), 1.5) << streams.summary.dump(1);
  EXPECT_GT(streams.summary["velocity_streams"]["switches_per_tracer_per_s"].get<double>(), 0.0);
  EXPECT_NEAR(streams.summary["velocity_streams"]["up_share_mean"].get<double>(), 0.5, 0.05);

  // The mean velocity is zero everywhere: without the streams the tracers never cross the zone.
  s.effects = {"transport", "walls", "tracer_volume_fraction", "residence_time", "field_average"};
  const Outcome mean = run(s, bouncingDatabase(s, balls), steps, discard);
  EXPECT_EQ(mean.summary["residence_time"]["stays"].get<std::int64_t>(), 0);
}

TEST(VelocityStreams, KeepsEveryTracerInsideAndAlphaPOfTheDatabase) {
  const BouncingBalls balls;
  const long tracers = 4000;
  Scene s = bouncingScene(tracers, kStreamEffects);
  const Outcome o = run(s, bouncingDatabase(s, balls), 1200, 200);
  ASSERT_EQ(o.cloud.size(), std::size_t(tracers));
  const Apparatus box(s.apparatus);
  for (std::size_t i = 0; i < o.cloud.size(); ++i) ASSERT_GE(box.signedDistance(o.cloud.position(i)), -1e-9) << i;
  // The time-averaged profile over height: alpha_P of the tracers against alpha_P^rec, layer by layer.
  const CartesianGrid grid = gridOf(s);
  std::string profile;
  double worst = 0.0;
  for (int j = 0; j < grid.shape[1]; ++j) {
    double t = 0.0, r = 0.0;
    for (int i = 0; i < grid.shape[0]; ++i) {
      t += o.alphaTracers[std::size_t(grid.flatIndex(i, j, 0))] / grid.shape[0];
      r += o.alphaRecurrence[std::size_t(grid.flatIndex(i, j, 0))] / grid.shape[0];
    }
    profile += std::to_string(j) + ": " + std::to_string(t) + " / " + std::to_string(r) + "\n";
    worst = std::max(worst, std::abs(t - r));
  }
  EXPECT_LT(worst, 0.02) << profile;
}

TEST(VelocityStreams, OneAndTwoThreadsAndAResumeAreBitIdentical) {
  const BouncingBalls balls;
  Scene s = bouncingScene(6000, kStreamEffects);  // above the parallel threshold
  s.effects.push_back("fluctuation");
  s.rcfd.d0 = 1e-3;
  auto db = bouncingDatabase(s, balls);
  const Outcome one = run(s, db, 60, 10, 1);
  const Outcome two = run(s, db, 60, 10, 2);
  const Outcome resumed = run(s, db, 60, 10, 2, 23);
  for (const Outcome* o : {&two, &resumed}) {
    EXPECT_TRUE(rcfd::test::bitIdentical(one.cloud.y, o->cloud.y));
    EXPECT_EQ(one.summary.dump(), o->summary.dump());
  }
}

TEST(VelocityStreams, ASceneWithoutItRunsAsBeforeAndAllocatesNothing) {
  // The same database with and without the spread fields: without the effect, the runs are identical.
  const BouncingBalls balls;
  Scene s = bouncingScene(3000, {"transport", "walls", "fluctuation", "tracer_volume_fraction", "residence_time"});
  s.rcfd.d0 = 1e-3;
  const CartesianGrid grid = gridOf(s);
  auto withSpread = bouncingDatabase(s, balls);
  auto without = database(s, 20, s.rcfd.dt, [&](int, double, FieldFrame& f) {
    balls.fill(grid, f);
    f.up_fraction.clear(), f.u_p_up.clear(), f.u_p_down.clear(), f.u_p_variance.clear();
  });
  const Outcome a = run(s, withSpread, 80, 10);
  const Outcome b = run(s, without, 80, 10);
  EXPECT_TRUE(rcfd::test::bitIdentical(a.cloud.y, b.cloud.y));
  EXPECT_EQ(a.summary.dump(), b.summary.dump());
  EXPECT_FALSE(a.summary.contains("velocity_streams"));
  TracerSimulation sim(s, without, sequentialPath(20, 10), {1, 5, 0});
  EXPECT_TRUE(sim.context().streamVelocity[0].empty());
  EXPECT_EQ(sim.allocatedBytes("velocity_streams"), 0u);
  EXPECT_FALSE(TracerEffectRegistry::needsVelocitySpread(s.effects));
}

TEST(VelocityStreams, ADatabaseWithoutTheSpreadIsAClearInputError) {
  const BouncingBalls balls;
  Scene s = bouncingScene(100, kStreamEffects);
  const CartesianGrid grid = gridOf(s);
  auto without = database(s, 5, s.rcfd.dt, [&](int, double, FieldFrame& f) {
    balls.fill(grid, f);
    f.up_fraction.clear(), f.u_p_up.clear(), f.u_p_down.clear(), f.u_p_variance.clear();
  });
  try {
    TracerSimulation sim(s, without, sequentialPath(5, 10), {1, 5, 0});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/frames/up_fraction"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("velocity_streams"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(TracerEffectRegistry::needsVelocitySpread(s.effects));
}

TEST(StayComparison, AReferenceStayOnTheStepLatticeSplitsIntoTheTwoCountsAroundIt) {
  double unseen = 0.0;
  // 0.0123 s on a 5 ms lattice: 2 steps with weight 0.54, 3 steps with 0.46; 2 ms: unseen 0.6 of the time.
  const auto a = analysis::onStepLattice({0.0123, 0.002}, 0.005, &unseen);
  ASSERT_EQ(a.values.size(), 3u);
  EXPECT_NEAR(a.values[0], 0.005, 1e-15);
  EXPECT_NEAR(a.weights[0], 0.4, 1e-12);
  EXPECT_NEAR(a.values[1], 0.010, 1e-15);
  EXPECT_NEAR(a.weights[1], 0.54, 1e-12);
  EXPECT_NEAR(a.values[2], 0.015, 1e-15);
  EXPECT_NEAR(a.weights[2], 0.46, 1e-12);
  EXPECT_NEAR(unseen, 0.3, 1e-12);
  // The expected lattice duration is the true one for stays the lattice sees at least once.
  const auto b = analysis::onStepLattice({0.0123}, 0.005);
  EXPECT_NEAR(analysis::summariseStays(b, 1, 1).mean_s, 0.0123, 1e-12);
  // A whole number of steps stays that number.
  const auto c = analysis::onStepLattice({0.015}, 0.005);
  ASSERT_EQ(c.values.size(), 1u);
  EXPECT_NEAR(c.values[0], 0.015, 1e-15);
}

TEST(StayComparison, StaysSampledAtStepEndsOfARandomPhaseMatchTheProjection) {
  // Simulate the lattice observation of stays of random length and phase: the projection predicts it.
  CounterRng rng(3, RngPurpose::Test, 0, 0);
  std::vector<double> durations;
  std::vector<std::int64_t> observed(64, 0);
  const double dt = 0.005;
  for (int i = 0; i < 200000; ++i) {
    const double d = 0.001 + 0.06 * rng.uniform() * rng.uniform();
    const double entry = 10.0 + dt * rng.uniform();
    durations.push_back(d);
    const auto k = std::int64_t(std::ceil((entry + d) / dt) - std::ceil(entry / dt));  // step ends inside
    ++observed[std::size_t(k)];
  }
  const auto projected = analysis::onStepLattice(durations, dt);
  const auto sampled = analysis::fromStepCounts(observed, dt);
  EXPECT_LT(analysis::ksDistance(projected, sampled), 0.005);
  const auto p = analysis::summariseStays(projected, 1000, 200), s = analysis::summariseStays(sampled, 1000, 200);
  EXPECT_NEAR(p.mean_s / s.mean_s, 1.0, 0.005);
  EXPECT_NEAR(p.crossingRate / s.crossingRate, 1.0, 0.005);
}

TEST(StayComparison, TheWindowCorrectionComparesAShortReferenceWithALongTracerRun) {
  // One stationary flow, observed twice: the reference for 2 s at 1 ms, the tracers for 8 s at their
  // 5 ms steps. A third of the stays are long (0.5-1.5 s), so the 2 s window loses many more of them.
  CounterRng rng(5, RngPurpose::Test, 0, 0);
  const double dt = 0.005, referenceWindow = 2.0, tracerWindow = 8.0;
  const int members = 10000;
  std::vector<double> reference;
  std::vector<std::int64_t> tracerCounts(400, 0);
  for (int m = 0; m < members; ++m) {
    double t = -3.0 * rng.uniform();  // the flow runs before both windows open
    while (t < tracerWindow) {
      t += -std::log(1.0 - rng.uniform());  // outside, 1 s on average
      const double d = rng.uniform() < 1.0 / 3.0 ? 0.5 + rng.uniform() : 0.01 + 0.2 * rng.uniform();
      if (t >= 0.0 && t + d <= referenceWindow) reference.push_back(std::round(d * 1000.0) / 1000.0);
      if (t >= 0.0 && t + d <= tracerWindow) {
        const auto k = std::int64_t(std::ceil((t + d) / dt) - std::ceil(t / dt));
        ++tracerCounts[std::size_t(k)];
      }
      t += d;
    }
  }
  const auto c = analysis::compareStays(tracerCounts, dt, members, tracerWindow, reference, members, referenceWindow);
  EXPECT_LT(std::abs(c.meanError()), 0.04) << c.toJson().dump(1);
  EXPECT_LT(std::abs(c.crossingRateError()), 0.04) << c.toJson().dump(1);
  EXPECT_LT(c.ksDistance, 0.03) << c.toJson().dump(1);
  EXPECT_EQ(c.longestCompared, 1.0);
  EXPECT_GT(c.tracersBeyond, 0.05);  // the stays above 1 s are left out on both sides
  EXPECT_GT(c.referenceBeyond, 0.02);

  // Without the correction the two windows disagree although the flow is the same.
  const auto rawTracers = analysis::summariseStays(analysis::fromStepCounts(tracerCounts, dt), members, tracerWindow);
  const auto rawReference = analysis::summariseStays(analysis::onStepLattice(reference, dt), members, referenceWindow);
  EXPECT_GT(rawTracers.mean_s / rawReference.mean_s, 1.15);
}
