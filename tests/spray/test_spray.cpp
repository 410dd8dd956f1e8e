// Spray stage: mass balance, empty bed, Poisson statistics of a well-mixed bed, the paper's one-hour
// numbers, determinism.
#include <gtest/gtest.h>

#include "../BitIdentical.hpp"
#include <omp.h>

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <random>
#include <utility>

#include "spray/Coverage.hpp"
#include "spray/DepositionEfficiency.hpp"
#include "spray/SprayState.hpp"
#include "SprayTestSupport.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {
nlohmann::json results(const TracerSimulation& sim, const std::string& name) {
  h5::File out(tempPath(name + ".h5"), h5::File::Mode::Create);
  nlohmann::json summary;
  sim.writeResults(out, summary);
  return summary;
}
double closure(const nlohmann::json& m) {
  return m["injected_kg"].get<double>() - (m["deposited_kg"].get<double>() + m["airborne_kg"].get<double>() +
                                           m["overspray_kg"].get<double>() + m["residual_kg"].get<double>());
}
}  // namespace

TEST(Spray, MassBalanceClosesOverAHundredThousandSteps) {
  Scene s = sprayBoxScene(400, 0.3, 0.08);
  // The particles rest (u_P = 0): the tracers need no transport, only the spray books are under test.
  s.effects = {"tracer_volume_fraction", "spray", "deposition", "coverage", "deposition_maps"};
  auto db = sprayBoxDatabase(s, 0.3, 0.08, 3.0);
  const std::int64_t steps = 100000;
  TracerSimulation sim(s, db, sequentialPath(db->frameCount(), steps + 2), {3, steps, 0});
  for (std::int64_t k = 0; k < steps; ++k) sim.step();
  const auto summary = results(sim, "balance");
  const auto& m = summary["mass_balance"];
  const double injected = m["injected_kg"].get<double>();
  EXPECT_NEAR(injected, s.spray.mass_rate * steps * s.rcfd.dt, 1e-12 * injected);
  EXPECT_LE(std::abs(closure(m)), 1e-9 * injected);
  EXPECT_GT(m["deposited_kg"].get<double>(), 0.1 * injected);
  EXPECT_GT(m["overspray_kg"].get<double>(), 0.0);
  // Deposited droplets are on the tracers or waiting in their cell (less than one droplet per cell).
  const double onTracers = m["on_tracers_kg"].get<double>(), pending = m["pending_in_cells_kg"].get<double>();
  EXPECT_NEAR(onTracers + pending, m["deposited_kg"].get<double>(), 1e-9 * injected);
}

TEST(Spray, DepositionMapsIntegrateToTheDepositedMass) {
  // Conservation of the maps: the time-averaged rate density [kg/(m3 s)], integrated over the open volume
  // of every cell and the collecting time, is the deposited mass. Statistics start at step 500, so the
  // deposits of the discarded steps must stay out of the maps.
  Scene s = sprayBoxScene(400, 0.3, 0.08);
  auto db = sprayBoxDatabase(s, 0.3, 0.08, 3.0);
  const std::int64_t steps = 3000, discard = 500;
  TracerSimulation sim(s, db, sequentialPath(db->frameCount(), steps + 2), {5, steps, discard});
  for (std::int64_t k = 0; k < discard; ++k) sim.step();
  const double depositedBefore = sim.context().spray->balance.deposited * sim.context().spray->dropletMass;
  for (std::int64_t k = discard; k < steps; ++k) sim.step();
  const std::string file = tempPath("maps.h5");
  nlohmann::json summary;
  {
    h5::File out(file, h5::File::Mode::Create);
    sim.writeResults(out, summary);
  }
  const double deposited = summary["mass_balance"]["deposited_kg"].get<double>() - depositedBefore;
  ASSERT_GT(deposited, 0.0);
  ASSERT_GT(depositedBefore, 0.0);
  const auto rate = h5::File(file, h5::File::Mode::ReadOnly).readDoubles("/deposition_maps/rate_density");
  const auto& open = std::as_const(sim).context().openVolume;
  ASSERT_EQ(rate.size(), open.size());
  double integral = 0.0;
  for (std::size_t c = 0; c < rate.size(); ++c) integral += rate[c] * open[c];
  integral *= double(steps - discard) * s.rcfd.dt;
  EXPECT_NEAR(integral, deposited, 1e-9 * deposited);
}

TEST(Spray, ParcelsRideAUniformUpdraftAndLeaveThroughTheOutlet) {
  // u_G^rec = U straight up everywhere: a parcel injected in step s has been carried (N - 1 - s) steps
  // of U dt each (sub-stepped: 1.5 cells per step), sideways not at all, and every parcel that left the
  // box left through the top outlet, none through a wall.
  constexpr double U = 3.0;
  Scene s = sprayBoxScene(400, 0.3, 0.08);
  s.effects = {"spray"};
  const CartesianGrid grid = gridOf(s);
  auto db = database(s, 6, s.rcfd.dt, [&](int, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) f.u_g[3 * c + 1] = float(U);
  });
  const std::int64_t steps = 40;  // 0.6 m of travel: the first parcels left through the top (0.2 m)
  TracerSimulation sim(s, db, sequentialPath(db->frameCount(), steps + 2), {7, steps, 0});
  for (std::int64_t k = 0; k < steps; ++k) sim.step();
  const SprayState& spray = *std::as_const(sim).context().spray;
  const double perStep = s.spray.parcels_per_s * s.rcfd.dt;  // 10 parcels injected per step
  // Injected on the nozzle within one cell of its head (SprayEffect::inject).
  const double reach = 0.5 * s.spray.nozzle_diameter + grid.spacing.minCoeff();
  ASSERT_GT(spray.parcels.size(), 100u);
  for (std::size_t j = 0; j < spray.parcels.size(); ++j) {
    const auto injectedAt = std::int64_t(double(spray.parcels.id[j]) / perStep);
    const double carried = double(steps - 1 - injectedAt) * U * s.rcfd.dt;
    const Eigen::Vector3d start = spray.parcels.position(j) - Eigen::Vector3d(0.0, carried, 0.0);
    ASSERT_LE((start - s.spray.nozzle_position).norm(), reach + 1e-12) << "parcel " << spray.parcels.id[j];
    ASSERT_LT(spray.parcels.y[j], s.apparatus.size.y());
  }
  const auto summary = results(sim, "updraft");
  const auto& m = summary["mass_balance"];
  EXPECT_GT(m["overspray_outlet_kg"].get<double>(), 0.0);
  EXPECT_EQ(m["overspray_wall_kg"].get<double>(), 0.0);
  EXPECT_LE(std::abs(closure(m)), 1e-12 * m["injected_kg"].get<double>());
  // The airborne parcels are those injected in the last 0.2 m / (U dt) = 13.3 steps, give or take one.
  const double airborneSteps = double(spray.parcels.size()) / perStep;
  EXPECT_GE(airborneSteps, 12.0);
  EXPECT_LE(airborneSteps, 15.0);
}

TEST(Spray, EmptyBedIsAllOversprayAndNoCoverage) {
  Scene s = sprayBoxScene(300, 0.0);
  s.process.bed_mass = 0.0;  // tracers carry no particles: alpha_P of the tracers is 0 everywhere
  auto db = sprayBoxDatabase(s, 0.0, 0.0, 4.0);
  const std::int64_t steps = 400;  // 2 s: parcels cross the 0.2 m box in 0.05 s
  TracerSimulation sim(s, db, sequentialPath(db->frameCount(), steps + 2), {5, steps, 0});
  for (std::int64_t k = 0; k < steps; ++k) sim.step();
  const auto summary = results(sim, "empty");
  const auto& m = summary["mass_balance"];
  EXPECT_EQ(m["deposited_kg"].get<double>(), 0.0);
  EXPECT_NEAR(m["overspray_kg"].get<double>() + m["airborne_kg"].get<double>(), m["injected_kg"].get<double>(),
              1e-12 * m["injected_kg"].get<double>());
  EXPECT_GT(summary["overspray_fraction"].get<double>(), 0.95);
  EXPECT_EQ(summary["coverage"]["mean"].get<double>(), 0.0);
  EXPECT_EQ(summary["coverage"]["p90"].get<double>(), 0.0);
}

TEST(Spray, WellMixedBedCollectsPoissonDropletCounts) {
  // One tracer per particle, tracers reshuffled uniformly every step, uniform deposition (one grid cell
  // holds the whole bed, so the deposited droplets of a step are shared by all tracers): every droplet
  // lands on a uniformly random particle, so droplet counts are Poisson and the coverage follows
  // 1 - (1 - f)^N, N ~ Poisson.
  const long tracers = 2000;
  Scene s = sprayBoxScene(tracers, 0.4, 0.2);
  s.grid.cell_size = s.apparatus.size;
  const double vp = std::numbers::pi / 6 * std::pow(s.particles.diameter, 3);
  s.process.bed_mass = tracers * s.particles.density * vp;  // exactly one particle per tracer
  s.spray.mass_rate = 5e-7;  // ~1.5e5 droplets in 5 s: a few tens per particle
  auto db = sprayBoxDatabase(s, 0.4, 0.2, 3.0);
  const std::int64_t steps = 1000;
  TracerSimulation sim(s, db, sequentialPath(db->frameCount(), steps + 2), {9, steps, 0});
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> ux(-0.05, 0.05), uy(0.0, 0.2), uz(0.0, 0.04);
  for (std::int64_t k = 0; k < steps; ++k) {
    auto& cloud = sim.context().cloud;
    for (std::size_t i = 0; i < cloud.size(); ++i) cloud.setPosition(i, Vec3(ux(rng), uy(rng), uz(rng)));
    sim.step();
  }
  const auto& droplets = sim.context().spray->tracerDroplets;
  double total = 0.0;
  for (double d : droplets) {
    ASSERT_EQ(d, std::floor(d)) << "whole droplets per particle";
    total += d;
  }
  const double mean = total / double(droplets.size());
  ASSERT_GT(mean, 5.0);
  // Kolmogorov-Smirnov distance between the empirical count distribution and Poisson(mean).
  std::vector<double> sorted(droplets.begin(), droplets.end());
  std::sort(sorted.begin(), sorted.end());
  double cdf = 0.0, pmf = std::exp(-mean), dMax = 0.0;
  std::size_t below = 0;
  for (int k = 0; k < int(10 * mean + 50); ++k) {
    cdf += pmf;
    while (below < sorted.size() && sorted[below] <= k) ++below;
    dMax = std::max(dMax, std::abs(double(below) / double(sorted.size()) - cdf));
    pmf *= mean / (k + 1);
  }
  EXPECT_LT(dMax, 1.63 / std::sqrt(double(sorted.size()))) << "KS distance at the 1% level, mean " << mean;
  // Coverage is a monotone map of the counts: the histogram of phi matches 1 - (1 - f)^N by the same test.
  const auto summary = results(sim, "poisson");
  const double f = summary["coverage"]["f"].get<double>();
  // E[1 - (1 - f)^N] = 1 - exp(-mean f) for N ~ Poisson(mean).
  EXPECT_NEAR(summary["coverage"]["mean"].get<double>(), 1.0 - std::exp(-mean * f),
              0.1 * f * mean);
}

TEST(Spray, DropletsPerParticleEqualsDepositedMassOverParticles) {
  Scene s = sprayBoxScene(1000, 0.5, 0.2);
  auto db = sprayBoxDatabase(s, 0.5, 0.2, 3.0);
  const std::int64_t steps = 300;
  TracerSimulation sim(s, db, sequentialPath(db->frameCount(), steps + 2), {4, steps, 0});
  for (std::int64_t k = 0; k < steps; ++k) sim.step();
  const auto summary = results(sim, "mean");
  const double realParticles = sim.cloud().particlesPerTracer * double(sim.cloud().size());
  const double dropletMass = sim.context().spray->dropletMass;
  const double expected = summary["mass_balance"]["on_tracers_kg"].get<double>() / (dropletMass * realParticles);
  // Exact up to the rounding of the kg conversion (whole droplets are summed exactly).
  EXPECT_NEAR(summary["droplets_per_tracer_mean"].get<double>(), expected, 1e-14 * expected);
  EXPECT_GT(expected, 0.0);
}

TEST(Spray, PaperParametersGiveNineteenThousandDropletsAndNinetyPercentCoverage) {
  // The paper's materials (Scene defaults): 1.5 kg of 1.8 mm particles, 0.3 kg/h of 40 um droplets for
  // one hour. Run compressed in time: the hour's spray mass within 2 s into a dense, well-mixed bed
  // (every parcel deposits in its first cell: no overspray), the particles represented by 2000 tracers
  // on 5 cm cells so each tracer passes the spray cell about 50 times.
  Scene s;
  s.apparatus.type = ApparatusSpec::Type::Box;
  s.apparatus.size = Vec3(0.1, 0.2, 0.05);
  s.apparatus.box_outlet_top = true;
  s.grid.cell_size = Vec3(0.05, 0.05, 0.05);
  s.rcfd.dt = 0.005;
  s.rcfd.tracers = 2000;
  s.effects = {"transport", "walls", "tracer_volume_fraction", "spray", "deposition", "coverage"};
  s.spray.nozzle_position = Vec3(0.0, 0.02, 0.025);
  s.spray.parcels_per_s = 2e4;  // 100 parcels per step
  const double hour = 3600.0, compressed = 2.0;
  s.spray.mass_rate = 0.3 / 3600.0 * hour / compressed;
  const CartesianGrid grid = gridOf(s);
  auto db = database(s, 6, s.rcfd.dt, [grid](int n, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      f.alpha_p[std::size_t(c)] = 0.55f;
      f.u_g[3 * c + 1] = float(2.0 + 0.1 * n);
    }
  });
  const std::int64_t steps = std::llround(compressed / s.rcfd.dt);
  TracerSimulation sim(s, db, sequentialPath(db->frameCount(), steps + 2), {6, steps, 0});
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> ux(-0.05, 0.05), uy(0.0, 0.2), uz(0.0, 0.05);
  for (std::int64_t k = 0; k < steps; ++k) {
    auto& cloud = sim.context().cloud;  // a well-mixed bed
    for (std::size_t i = 0; i < cloud.size(); ++i) cloud.setPosition(i, Vec3(ux(rng), uy(rng), uz(rng)));
    sim.step();
  }
  const auto summary = results(sim, "paper");
  const double realParticles = sim.cloud().particlesPerTracer * double(sim.cloud().size());
  EXPECT_NEAR(realParticles, 472850, 0.005 * 472850);
  EXPECT_LT(summary["overspray_fraction"].get<double>(), 0.01);
  EXPECT_NEAR(summary["droplets_per_tracer_mean"].get<double>(), 1.9e4, 0.03 * 1.9e4);
  // Each tracer visits the spray cell ~Poisson(50) times: E[phi] = 1 - exp(50 (exp(-f N / 50) - 1))
  // = 0.899 for f N = 2.35, the coverage of the mean droplet number 0.905.
  EXPECT_NEAR(summary["coverage"]["mean"].get<double>(), 0.90, 0.01);
  EXPECT_NEAR(summary["coverage"]["median"].get<double>(), 0.90, 0.015);
}

TEST(Spray, SortingKeepsEveryTracersDropletsAndPosition) {
  Scene s = sprayBoxScene(6000, 0.4, 0.1);
  auto db = sprayBoxDatabase(s, 0.4, 0.1, 3.0);
  const std::int64_t steps = 40;
  TracerSimulation sim(s, db, sequentialPath(db->frameCount(), steps + 2), {21, steps, 0, true, 0});
  for (std::int64_t k = 0; k < steps; ++k) sim.step();
  const TracerSimulation& view = sim;
  const auto& cloud = view.cloud();
  const auto droplets = cloud.inIdOrder(view.context().spray->tracerDroplets);
  const auto x = cloud.inIdOrder(cloud.x), y = cloud.inIdOrder(cloud.y);
  const auto idsBefore = cloud.id;
  ASSERT_GT(*std::max_element(droplets.begin(), droplets.end()), 0.0);
  sim.sortTracers();
  EXPECT_NE(cloud.id, idsBefore);  // the tracers did move in memory
  EXPECT_EQ(cloud.inIdOrder(view.context().spray->tracerDroplets), droplets);
  EXPECT_EQ(cloud.inIdOrder(cloud.x), x);
  EXPECT_EQ(cloud.inIdOrder(cloud.y), y);
  // Sorted: cells never decrease along the storage order.
  const CartesianGrid& grid = view.context().grid;
  for (std::size_t i = 1; i < cloud.size(); ++i) {
    ASSERT_LE(grid.flatIndexOf(cloud.position(i - 1)), grid.flatIndexOf(cloud.position(i))) << i;
  }
}

TEST(Spray, OneAndTwoThreadsAndResumeAreBitIdentical) {
  Scene s = sprayBoxScene(6000, 0.4, 0.1);  // above the parallel threshold: threads really split work
  s.effects.push_back("fluctuation");
  auto db = sprayBoxDatabase(s, 0.4, 0.1, 3.0);
  const std::int64_t steps = 60;
  auto run = [&](int threads, std::int64_t checkpointAt) {
    omp_set_num_threads(threads);
    const RecurrencePath path = sequentialPath(db->frameCount(), steps + 2);
    // Re-sorted by cell every 7 steps: the droplets per tracer move with their tracers, across the resume.
    const TracerRunSettings settings{21, steps, 0, true, 7};
    TracerSimulation sim(s, db, path, settings);
    std::unique_ptr<TracerSimulation> resumed;
    TracerSimulation* active = &sim;
    const std::string checkpoint = tempPath("spray-checkpoint.h5");
    for (std::int64_t k = 0; k < steps; ++k) {
      if (k == checkpointAt) {
        sim.saveCheckpoint(checkpoint);
        resumed = std::make_unique<TracerSimulation>(s, db, path, settings);
        resumed->loadCheckpoint(checkpoint);
        active = resumed.get();
      }
      active->step();
    }
    omp_set_num_threads(2);
    return std::make_pair(results(*active, "det"), active->context().spray->tracerDroplets);
  };
  const auto [one, dropletsOne] = run(1, -1);
  const auto [two, dropletsTwo] = run(2, -1);
  const auto [resumed, dropletsResumed] = run(2, 23);
  EXPECT_EQ(one.dump(), two.dump());
  EXPECT_EQ(one.dump(), resumed.dump());
  ASSERT_EQ(dropletsOne.size(), dropletsTwo.size());
  EXPECT_TRUE(rcfd::test::bitIdentical(dropletsOne, dropletsTwo));
  EXPECT_TRUE(rcfd::test::bitIdentical(dropletsOne, dropletsResumed));
  EXPECT_GT(one["mass_balance"]["on_tracers_kg"].get<double>(), 0.0);
}

TEST(Spray, AParcelDepositsAlongItsWholeFlightWhateverTheRcfdStep) {
  // A uniform bed (the same number of resting tracers in every cell) in a uniform updraft U: over any
  // piece of its flight a parcel keeps exp(-k t) of its droplets (the exponential form of Eq. 11), with k
  // fixed by alpha_P and the slip U. So an airborne parcel holds N0 exp(-k t) after t in the air, and a
  // parcel that left through the top took between (0.2 m - y_start) / U to get there, for an rCFD step
  // of 1 ms (under a cell per step) as for 20 ms (8 cells per step, in sub-steps): the deposit follows
  // the parcel's path, not the cells it ends its steps in.
  constexpr double U = 4.0, kHeight = 0.2;
  for (const double dt : {1e-3, 5e-3, 20e-3}) {
    SCOPED_TRACE("dt = " + std::to_string(dt));
    Scene s = sprayBoxScene(6400, 0.006);  // a dilute bed: about half the droplets reach the top
    s.effects = {"tracer_volume_fraction", "spray", "deposition"};
    s.rcfd.dt = dt;
    const CartesianGrid grid = gridOf(s);
    ASSERT_EQ(grid.cellCount() * 8, s.rcfd.tracers);
    auto db = database(s, 4, dt, [&](int, double, FieldFrame& f) {
      for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
        f.alpha_p[std::size_t(c)] = 0.006f;
        f.u_g[3 * c + 1] = float(U);
      }
    });
    const auto steps = std::int64_t(std::llround(0.3 / dt));
    TracerSimulation sim(s, db, sequentialPath(db->frameCount(), steps + 2), {11, steps, 0});
    {  // eight tracers per cell, on a lattice: the tracers' alpha_P is the same in every cell
      TracerCloud& cloud = sim.context().cloud;
      std::size_t i = 0;
      for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
        const auto ijk = grid.cellIjk(c);
        const Eigen::Vector3d centre = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
        for (int corner = 0; corner < 8; ++corner) {
          const Eigen::Vector3d offset(corner & 1 ? 0.25 : -0.25, corner & 2 ? 0.25 : -0.25, corner & 4 ? 0.25 : -0.25);
          cloud.setPosition(i++, centre + grid.spacing.cwiseProduct(offset));
        }
      }
    }
    for (std::int64_t k = 0; k < steps; ++k) sim.step();
    const TracerContext& ctx = std::as_const(sim).context();
    const SprayState& spray = *ctx.spray;
    const float alpha = ctx.tracerAlpha.at(0);
    ASSERT_GT(alpha, 0.0f);
    for (const float a : ctx.tracerAlpha) ASSERT_EQ(a, alpha);
    const auto model = DepositionModelRegistry::create(s.spray.deposition_model);
    const DepositionConstants constants = depositionConstants(s);
    const double k = -std::log1p(-model->efficiency({double(alpha), U, 1e-3}, constants)) / 1e-3;
    const double n0 = spray.dropletsPerParcel;
    const double tMin = (kHeight - 0.005 - 0.5 * s.spray.nozzle_diameter - 0.01) / U;
    const double tMax = (kHeight - 0.005) / U;
    ASSERT_GT(k * tMax, 0.2);  // a deposit to measure, and parcels that leave with most droplets too
    ASSERT_LT(k * tMax, 3.0);

    const auto perStep = std::int64_t(std::llround(s.spray.parcels_per_s * dt));
    ASSERT_GT(spray.parcels.size(), 0u);
    for (std::size_t j = 0; j < spray.parcels.size(); ++j) {
      const std::int64_t injectedIn = spray.parcels.id[j] / perStep;
      const double airborne = double(steps - 1 - injectedIn) * dt;
      ASSERT_NEAR(spray.parcels.droplets[j], n0 * std::exp(-k * airborne), 1e-6 * n0) << "parcel " << j;
    }
    const auto summary = results(sim, "along-path");
    const auto& m = summary["mass_balance"];
    EXPECT_EQ(m["overspray_wall_kg"].get<double>(), 0.0);
    EXPECT_EQ(m["residual_kg"].get<double>(), 0.0);
    EXPECT_LE(std::abs(closure(m)), 1e-12 * m["injected_kg"].get<double>());
    const double left = double(summary["parcels"]["injected"].get<std::int64_t>()) - double(spray.parcels.size());
    ASSERT_GT(left, 20.0);
    const double perParcel = m["overspray_outlet_kg"].get<double>() / spray.dropletMass / left;
    EXPECT_GE(perParcel, n0 * std::exp(-k * tMax) * (1.0 - 1e-9));
    EXPECT_LE(perParcel, n0 * std::exp(-k * tMin) * (1.0 + 1e-9));
  }
}
