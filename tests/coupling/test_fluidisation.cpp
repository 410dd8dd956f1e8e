// The minimum fluidisation velocity of a flat bed of the paper's particles (1.8 mm, 1040 kg/m3) in a
// small box fed through its whole bottom, determined as the experiments behind the Wen-Yu correlation
// determine it (Kunii & Levenspiel, Fluidization Engineering, 2nd ed., ch. 3): the bed is fluidised,
// the gas is then reduced slowly (the defluidisation curve, free of the packing history and the
// overshoot of the poured bed), and U_mf is where the packed-bed branch of the pressure drop, fitted
// with Ergun's form a U + b U^2, meets the bed weight per area. Against Wen-Yu, within 20%.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <vector>

#include "CouplingTestSupport.hpp"

namespace rcfd {
namespace {

double envOr(const char* name, double value) {
  const char* v = std::getenv(name);
  return v ? std::atof(v) : value;
}

struct ErgunFit {
  double a = 0.0, b = 0.0;  ///< dp = a U + b U^2 [Pa s/m, Pa s2/m2]
  double rms = 0.0;         ///< root-mean-square residual [Pa]
};

/// Least-squares fit of dp = a U + b U^2 (through the origin: no flow, no drag).
ErgunFit fitErgunForm(const std::vector<double>& u, const std::vector<double>& dp) {
  double s2 = 0, s3 = 0, s4 = 0, r1 = 0, r2 = 0;
  for (std::size_t i = 0; i < u.size(); ++i) {
    const double x = u[i];
    s2 += x * x, s3 += x * x * x, s4 += x * x * x * x, r1 += x * dp[i], r2 += x * x * dp[i];
  }
  const double det = s2 * s4 - s3 * s3;
  ErgunFit f{(r1 * s4 - r2 * s3) / det, (s2 * r2 - s3 * r1) / det, 0.0};
  for (std::size_t i = 0; i < u.size(); ++i) f.rms += std::pow(f.a * u[i] + f.b * u[i] * u[i] - dp[i], 2);
  f.rms = std::sqrt(f.rms / double(u.size()));
  return f;
}

/// Mean solid fraction of the parcels whose centres lie in y0 <= y < y1 (the bed's interior).
double bedSolidFraction(const DemParticles& p, double area, double y0, double y1) {
  double v = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.x[i].y() >= y0 && p.x[i].y() < y1) v += 4.0 / 3.0 * std::numbers::pi * std::pow(p.radius[i], 3);
  return v / (area * (y1 - y0));
}

/// One defluidisation run: U_mf from the fitted packed branch, and what it is compared with.
struct FluidisationRun {
  double uMf = 0.0;       ///< [m/s]
  double wenYu = 0.0;     ///< Wen-Yu's U_mf for these particles [m/s]
  double ergunUmf = 0.0;  ///< Ergun's U_mf at the defluidised bed's own porosity [m/s]
};

// A 5 cm x 5 cm box (14 parcel diameters), cg 2 parcels of 3.6 mm in 5 mm cells, a
// bed of 1570 parcels poured and settled (DEM only, as in the database job), about 2.6 cm high. The
// gas rises to 0.9 m/s (1.6 Wen-Yu) in 0.2 s, stays 0.15 s (the bed slugs), and falls to 0.2 m/s in
// 0.7 s (1 m/s^2: halving the rate moves U_mf by 1-3%, docs/physics.md). The packed-bed branch is the
// part of the decreasing curve after the pressure drop last exceeded 0.9 W/A and below 0.75 W/A.
// RCFD_FLUID_CSV=FILE writes the (t, U, dp) series; RCFD_FLUID_* change the protocol (see envOr).
// U_mf = 1.14-1.19 Wen-Yu over seeds and rates (docs/physics.md "Minimum fluidisation"); 16-19 s on one
// core per bed.
void measureFluidisation(std::uint64_t seed, FluidisationRun& run) {
  const double width = envOr("RCFD_FLUID_WIDTH", 0.05);
  const double uHigh = envOr("RCFD_FLUID_UHIGH", 0.9), uLow = envOr("RCFD_FLUID_ULOW", 0.2);
  const double upTime = envOr("RCFD_FLUID_UP", 0.2), holdTime = envOr("RCFD_FLUID_HOLD", 0.15);
  const double downTime = envOr("RCFD_FLUID_DOWN", 0.7);
  const double kneeFraction = 0.9, packedFraction = envOr("RCFD_FLUID_PACKED", 0.75);
  Scene s = test::couplingBox(Vec3(width, 0.08, width), 0.005, uHigh * width * width);
  s.dem.coarse_graining = 2.0;
  s.dem.time_step = 4e-5;  // 0.28 of the Rayleigh time of the 3.6 mm parcels
  s.dem.coupling_interval = 10;
  s.gas.max_time_step = 4e-4;
  s.dem.settle_time = 0.15;
  s.process.bed_mass = envOr("RCFD_FLUID_BED", 0.04) * width * width / 0.0025;
  s.effects = {"gas", "drag", "rolling_friction"};
  gas::GasOptions go;
  go.boxBottomInlet = true;
  CfdDemSimulation sim(s, seed, go);
  sim.setFlowFactor(0.0);
  sim.fillAndSettle();
  const DemParticles& p = sim.dem().particles();
  const double area = width * width;
  double weight = 0.0, solidVolume = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    weight += p.mass[i] * 9.81 * (1 - s.gas.density / s.particles.density);
    solidVolume += 4.0 / 3.0 * std::numbers::pi * std::pow(p.radius[i], 3);
  }
  const double target = weight / area;  // W/A [Pa]
  const double pouredPacking = bedSolidFraction(p, area, 0.005, 0.02);
  const double hydrostatic = s.gas.density * 9.81 * s.apparatus.size.y();  // from y = 0 to the top
  const auto& g = sim.grid();
  // The bed's pressure drop from the inlet face (y = 0: the area mean of the two lowest cell rows
  // extrapolated to it, since the lowest half cell holds a tenth of the bed) to the outlet, less the
  // gas's own hydrostatic head.
  auto bedPressureDrop = [&] {
    const auto& pr = sim.gasSolver()->pressure();
    double p0 = 0.0, p1 = 0.0;
    for (int k = 0; k < g.shape[2]; ++k)
      for (int i = 0; i < g.shape[0]; ++i) {
        p0 += pr[std::size_t(g.flatIndex(i, 0, k))];
        p1 += pr[std::size_t(g.flatIndex(i, 1, k))];
      }
    const double n = double(g.shape[0] * g.shape[2]);
    return (1.5 * p0 - 0.5 * p1) / n - hydrostatic;
  };
  const double t0 = sim.time(), downStart = upTime + holdTime, total = downStart + downTime;
  std::vector<double> ts, us, dps;
  while (sim.time() - t0 < total) {
    const double t = sim.time() - t0;
    const double u = t < upTime      ? uHigh * t / upTime
                     : t < downStart ? uHigh
                                     : uHigh + (uLow - uHigh) * (t - downStart) / downTime;
    sim.setFlowFactor(u / uHigh);
    sim.step(sim.demStep() + s.dem.coupling_interval);
    ts.push_back(t), us.push_back(u), dps.push_back(bedPressureDrop());
  }
  const double defluidisedPacking = bedSolidFraction(p, area, 0.005, 0.02);
  if (const char* csv = std::getenv("RCFD_FLUID_CSV")) {
    std::ofstream out(csv);
    out << "# W/A " << target << " Pa\n";
    for (std::size_t i = 0; i < us.size(); ++i) out << ts[i] << " " << us[i] << " " << dps[i] << "\n";
  }
  // The decreasing curve: the bed is fluidised while dp carries (nearly) its weight; the packed
  // branch begins after the last such sample and is fitted where dp is well below the weight.
  std::size_t knee = 0;
  double fluidisedSum = 0.0;
  int fluidisedCount = 0;
  for (std::size_t i = 0; i < ts.size(); ++i)
    if (ts[i] >= downStart && dps[i] >= kneeFraction * target) knee = i;
  for (std::size_t i = 0; i < ts.size(); ++i)
    if (ts[i] >= downStart && i <= knee) fluidisedSum += dps[i], ++fluidisedCount;
  ASSERT_GT(fluidisedCount, 0) << "the bed was not fluidised at " << uHigh << " m/s";
  std::vector<double> uPacked, dpPacked;
  for (std::size_t i = knee + 1; i < ts.size(); ++i)
    if (dps[i] <= packedFraction * target) uPacked.push_back(us[i]), dpPacked.push_back(dps[i]);
  ASSERT_GE(uPacked.size(), 100u) << "too few samples on the packed-bed branch";
  const ErgunFit fit = fitErgunForm(uPacked, dpPacked);
  ASSERT_GT(fit.a, 0.0);
  ASSERT_GE(fit.b, 0.0);
  // The branch is a packed bed: Ergun's form describes it to within 2% of the weight.
  EXPECT_LT(fit.rms, 0.02 * target);
  const double uMf = (-fit.a + std::sqrt(fit.a * fit.a + 4 * fit.b * target)) / (2 * fit.b);

  const double rhoG = s.gas.density, mu = rhoG * s.gas.kinematic_viscosity, d = s.particles.diameter;
  const double ar = d * d * d * rhoG * (s.particles.density - rhoG) * 9.81 / (mu * mu);
  const double wenYu = (std::sqrt(33.7 * 33.7 + 0.0408 * ar) - 33.7) * mu / (rhoG * d);
  // Ergun's coefficients for the defluidised bed (solid height V/A, porosity of its interior).
  const double eps = 1 - defluidisedPacking, hs = solidVolume / area;
  const double ergunA = 150 * mu * hs * (1 - eps) / (eps * eps * eps * d * d);
  const double ergunB = 1.75 * rhoG * hs / (eps * eps * eps * d);
  const double ergunUmf = (-ergunA + std::sqrt(ergunA * ergunA + 4 * ergunB * target)) / (2 * ergunB);
  std::cerr << "W/A " << target << " Pa; fluidised mean dp " << fluidisedSum / fluidisedCount / target
            << " W/A; packed fit U " << uPacked.back() << ".." << uPacked.front() << " m/s: a " << fit.a
            << " b " << fit.b << " (Ergun at eps " << eps << ": a " << ergunA << " b " << ergunB << ") rms "
            << fit.rms << " Pa; packing poured " << pouredPacking << " defluidised " << defluidisedPacking
             << "; U_mf " << uMf << " m/s, Ergun at eps " << ergunUmf << " m/s, Wen-Yu " << wenYu << " m/s, ratio " << uMf / wenYu << "\n";
  // What is left of the difference to Wen-Yu is the bed's porosity: Ergun's U_mf at the porosity of
  // this bed's interior (0.42-0.44 here, Wen-Yu's constants correspond to about 0.40) is the fitted one.
  EXPECT_NEAR(uMf, ergunUmf, 0.1 * ergunUmf) << "seed " << seed << ": Ergun at eps " << eps;
  run = {uMf, wenYu, ergunUmf};
}

// The slugging bed is chaotic: a rounding-level change of the run (an operation reordered, the DEM's
// neighbour-list skin) moves one bed's ratio by ~0.02-0.04, as much as another poured bed does. The
// criterion is therefore the mean over three poured beds (seeds 5, 1, 2; RCFD_FLUID_SEED runs one).
TEST(Fluidisation, MinimumFluidisationVelocityWithinTwentyPercentOfWenYu) {
  std::vector<std::uint64_t> seeds = {5, 1, 2};
  if (const char* one = std::getenv("RCFD_FLUID_SEED")) seeds = {std::uint64_t(std::atoll(one))};
  double sum = 0.0, wenYu = 0.0;
  for (const std::uint64_t seed : seeds) {
    FluidisationRun run;
    measureFluidisation(seed, run);
    if (HasFatalFailure()) return;
    std::cerr << "seed " << seed << ": U_mf / Wen-Yu " << run.uMf / run.wenYu << "\n";
    sum += run.uMf;
    wenYu = run.wenYu;
  }
  const double mean = sum / double(seeds.size());
  RecordProperty("umf_over_wen_yu", std::to_string(mean / wenYu));
  EXPECT_NEAR(mean, wenYu, 0.2 * wenYu) << "mean U_mf of " << seeds.size() << " beds; Wen-Yu " << wenYu << " m/s";
}

}  // namespace
}  // namespace rcfd
