// Physics of the tracer stages against analytic cases: mixing under solid-body rotation with the
// fluctuation model, relaxation of an over-packed half, plug-flow residence times, terminal velocity.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "TracerTestSupport.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {
/// Upper-tail probability of the chi-square distribution with k degrees of freedom (Wilson-Hilferty).
double chiSquarePValue(double x, int k) {
  const double z = (std::cbrt(x / k) - (1.0 - 2.0 / (9.0 * k))) / std::sqrt(2.0 / (9.0 * k));
  return 0.5 * std::erfc(z / std::sqrt(2.0));
}
}  // namespace

TEST(Fluctuation, SolidBodyRotationKeepsTracersUniform) {
  // A rotating cell filling the box: stream function psi = A sin(pi X) sin(pi Y) (X, Y in [0, 1]), which
  // turns like a solid body near the centre (omega = A pi^2 / L^2, one revolution per 100 steps), is
  // divergence-free and tangent to the walls. With uniform alpha_P^rec and the fluctuation model on,
  // the tracers must stay uniform after 10 revolutions.
  const double dt = 0.01, L = 0.1, omega = 2.0 * std::numbers::pi / (100 * dt);
  const double A = omega * L * L / (std::numbers::pi * std::numbers::pi);
  Scene s = boxScene({L, L, 0.02}, 0.01, 2000, dt,
                     {"transport", "walls", "fluctuation", "tracer_volume_fraction"}, 0.3);
  s.rcfd.d0 = 2e-3;
  const CartesianGrid grid = gridOf(s);
  auto db = database(s, 4, dt, [&](int, double, FieldFrame& f) {
    const double k = std::numbers::pi / L;
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      const auto p = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
      const double X = (p.x() + L / 2) * k, Y = p.y() * k;
      f.alpha_p[std::size_t(c)] = 0.3f;
      f.u_p[3 * c] = float(A * k * std::sin(X) * std::cos(Y));
      f.u_p[3 * c + 1] = float(-A * k * std::cos(X) * std::sin(Y));
    }
  });
  const std::int64_t steps = 1000;  // 10 revolutions
  TracerSimulation sim(s, db, sequentialPath(4, steps + 2), {7, steps, 0});
  for (std::int64_t k = 0; k < steps; ++k) sim.step();
  ASSERT_EQ(sim.cloud().size(), 2000u);
  // Chi-square over the 10 x 10 columns of cells (z is 2 cells deep and summed).
  std::vector<int> counts(100, 0);
  for (std::size_t i = 0; i < sim.cloud().size(); ++i) {
    const auto c = grid.cellOf(sim.cloud().position(i));
    ++counts[std::size_t(c[1] * 10 + c[0])];
  }
  const double expected = 20.0;
  double chi2 = 0.0;
  for (int n : counts) chi2 += (n - expected) * (n - expected) / expected;
  EXPECT_GT(chiSquarePValue(chi2, 99), 1e-3) << "chi2 = " << chi2;
}

TEST(Fluctuation, RelaxesAnOverpackedHalfAndDoesNothingWithoutD0) {
  // Frame 0 holds the bed in the left half (the tracers start there); all later frames are uniform at
  // alpha_P^rec = 0.25 and u_P = 0. With D0 > 0 the RMS difference between the tracers' and the
  // recurrence alpha_P (the penalty over all cells) falls toward its noise floor; with D0 = 0 nothing
  // moves.
  const double dt = 0.005;
  auto run = [&](double d0) {
    Scene s = boxScene({0.04, 0.02, 0.01}, 0.005, 4000, dt,
                       {"transport", "walls", "fluctuation", "tracer_volume_fraction"}, 0.25);
    s.rcfd.d0 = d0;
    const CartesianGrid grid = gridOf(s);
    auto db = database(s, 50, dt, [&](int n, double, FieldFrame& f) {
      for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
        const auto ijk = grid.cellIjk(c);
        f.alpha_p[std::size_t(c)] = n == 0 ? (ijk[0] < 4 ? 0.5f : 0.0f) : 0.25f;
      }
    });
    RecurrencePath path;  // frame 0 (the packed half) only at the start, then frames 1..49 cycling
    path.frames.push_back(0);
    for (int k = 1; k < 2002; ++k) path.frames.push_back(1 + (k - 1) % 49);
    const std::int64_t steps = 2000;
    TracerSimulation sim(s, db, path, {11, steps, 0});
    const TracerCloud start = sim.cloud();
    auto rms = [&] {
      double sum = 0.0;
      for (float a : sim.context().tracerAlpha) sum += (a - 0.25) * (a - 0.25);
      return std::sqrt(sum / double(sim.context().tracerAlpha.size()));
    };
    sim.step();
    const double first = rms();
    for (std::int64_t k = 1; k < steps; ++k) sim.step();
    const double last = rms();
    double moved = 0.0;
    // The tracers are re-sorted by cell as they go: index i holds tracer id[i] (start is in id order).
    for (std::size_t i = 0; i < start.size(); ++i) {
      moved += (sim.cloud().position(i) - start.position(std::size_t(sim.cloud().id[i]))).norm();
    }
    return std::make_tuple(moved, first, last);
  };
  const auto [movedWithout, firstWithout, lastWithout] = run(0.0);
  EXPECT_EQ(movedWithout, 0.0);
  EXPECT_EQ(firstWithout, lastWithout);
  EXPECT_NEAR(firstWithout, 0.25, 0.01);
  const auto [movedWith, firstWith, lastWith] = run(1e-2);
  EXPECT_GT(movedWith, 0.0);
  // Noise floor: ~62 tracers per cell, Poisson spread 0.25 / sqrt(62) = 0.032.
  EXPECT_LT(lastWith, 0.3 * firstWith) << "first " << firstWith << " last " << lastWith;
}

TEST(ResidenceTime, PlugFlowGivesZoneHeightOverSpeed) {
  // A nearly cylindrical zone (apex far below, 1 deg half-angle) spanning the box's width; the tracers
  // start below it and rise at U: every stay lasts (y_max - y_min) / U, within one step.
  const double dt = 0.01, U = 1.0;
  Scene s = boxScene({0.1, 1.0, 0.05}, 0.025, 500, dt, {"transport", "walls", "residence_time"}, 0.01);
  s.spray.spray_zone.apex = Vec3(0.0, -10.0, 0.025);
  s.spray.spray_zone.half_angle_deg = 1.0;
  s.spray.spray_zone.y_min = 0.3;
  s.spray.spray_zone.y_max = 0.6;
  const CartesianGrid grid = gridOf(s);
  auto db = database(s, 10, dt, [&](int n, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      f.alpha_p[std::size_t(c)] = n == 0 ? (ijk[1] < 8 ? 0.3f : 0.0f) : 0.01f;  // start below y = 0.2
      f.u_p[3 * c + 1] = float(U);
    }
  });
  RecurrencePath path = sequentialPath(10, 80);
  for (std::size_t k = 1; k < path.frames.size(); ++k) path.frames[k] = 1 + int(k % 9);
  const std::int64_t steps = 75;  // tracers reach at most y = 0.95: nobody comes back down
  TracerSimulation sim(s, db, path, {5, steps, 0});
  for (std::int64_t k = 0; k < steps; ++k) sim.step();
  h5::File out(tempPath("plug.h5"), h5::File::Mode::Create);
  nlohmann::json summary;
  sim.writeResults(out, summary);
  const auto counts = out.readInt64s("/residence_time/duration_steps_counts");
  std::int64_t stays = 0;
  for (std::size_t d = 0; d < counts.size(); ++d) {
    if (counts[d] == 0) continue;
    stays += counts[d];
    EXPECT_NEAR(double(d) * dt, 0.3 / U, dt + 1e-12) << counts[d] << " stays of " << d << " steps";
  }
  EXPECT_EQ(stays, 500);
  EXPECT_NEAR(summary["residence_time"]["mean_s"].get<double>(), 0.3, dt);
}

TEST(FreeFlight, TerminalVelocityMatchesDragBalance) {
  // alpha_P^rec = 0.01 < 0.02 everywhere: free flight in still gas. Terminal speed v solves
  // g tau_St = v f(Re(v)) with Schiller-Naumann f.
  const double dt = 0.005;
  Scene s = boxScene({0.1, 80.0, 0.1}, 0.05, 4, dt, {"transport", "walls", "free_flight"}, 0.001);
  s.grid.cell_size = Vec3(0.05, 1.0, 0.05);
  const CartesianGrid grid = gridOf(s);
  auto db = database(s, 4, dt, [&](int, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      f.alpha_p[std::size_t(c)] = ijk[1] >= 78 ? 0.01f : 0.0f;  // the tracers start near the top
    }
  });
  const std::int64_t steps = 1200;  // 6 s: many relaxation times
  TracerSimulation sim(s, db, sequentialPath(4, steps + 2), {3, steps, 0});
  for (std::int64_t k = 0; k < steps; ++k) sim.step();
  const auto& p = s.particles;
  const double tauSt = p.density * p.diameter * p.diameter / (18.0 * s.gas.density * s.gas.kinematic_viscosity);
  const double g = 9.81;
  double lo = 0.0, hi = 100.0;
  for (int it = 0; it < 200; ++it) {
    const double v = 0.5 * (lo + hi);
    const double re = v * p.diameter / s.gas.kinematic_viscosity;
    const double f = re < 1000.0 ? 1.0 + 0.15 * std::pow(re, 0.687) : 0.44 * re / 24.0;
    (v * f < g * tauSt ? lo : hi) = v;
  }
  const double terminal = 0.5 * (lo + hi);
  for (std::size_t i = 0; i < sim.cloud().size(); ++i) {
    EXPECT_NEAR(-sim.cloud().vy[i], terminal, 0.01 * terminal);
    EXPECT_GT(sim.cloud().y[i], 0.0);
  }
}
