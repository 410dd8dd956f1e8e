// rcfd-bench cfddem: the coupled CFD-DEM of examples/quick.json (embedded) as the database job runs it.
// The bed is filled and settled once (DEM only) and cached as a checkpoint in $TMPDIR; the gas is then
// ramped up over `ramp` s (untimed) and the timed part runs `seconds` of coupled simulation. Reports
// wall (and CPU) seconds per simulated second, parcel-steps per second including the gas, the share of
// the gas, the wall time of each DEM phase and the DEM steps per neighbour-list build, the mean DEM
// sub-steps per gas step and the largest alpha_P.
//   --quick: a tenth of the bed, ramp 0.02 s, 0.02 s timed (seconds).   Full: ramp 0.1 s, 0.2 s timed.
//   RCFD_BENCH_CFDDEM_SECONDS=T: time T s instead; RCFD_BENCH_CFDDEM_RAMP=R: ramp R s;
//   RCFD_BENCH_CFDDEM_SCENE=path: another scene file; RCFD_BENCH_CFDDEM_SAVE=path: the final state
//   into a checkpoint; RCFD_BENCH_CFDDEM_START=path: start from such a checkpoint or from a database
//   job's checkpoint.h5 (no fill, no ramp);
//   RCFD_BENCH_CFDDEM_PGM=prefix: also writes alpha_P (mean over z) as prefix-N.pgm every 0.2 s and
//   prefix-alpha.pgm at the end. A progress line every 0.05 s simulated goes to stderr.
//   RCFD_BENCH_CFDDEM_SERIES=path: time, pressure drop and DEM steps of every coupling step.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "BenchRegistry.hpp"
#include "cfddem/CfdDemSimulation.hpp"
#include "cfddem/gas/GasSolver.hpp"
#include "core/EmbeddedFiles.hpp"
#include "core/Hdf5.hpp"
#include "scene/SceneLoader.hpp"

namespace rcfd::bench {
namespace {

double envOr(const char* name, double fallback) {
  const char* v = std::getenv(name);
  return v ? std::atof(v) : fallback;
}

double cpuSeconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

/// alpha_P averaged over z as an 8-bit image, black 0, white 0.65, y up.
void writeAlphaImage(const CfdDemSimulation& sim, const std::string& path) {
  const auto a = sim.particleFraction();
  const auto& g = sim.grid();
  std::ofstream out(path, std::ios::binary);
  out << "P5\n" << g.shape[0] << " " << g.shape[1] << "\n255\n";
  for (int j = g.shape[1] - 1; j >= 0; --j)
    for (int i = 0; i < g.shape[0]; ++i) {
      double s = 0.0;
      for (int k = 0; k < g.shape[2]; ++k) s += a[std::size_t(g.flatIndex(i, j, k))];
      out.put(char(std::lround(std::min(1.0, s / g.shape[2] / 0.65) * 255)));
    }
}

nlohmann::json runCfdDem(const Options& o) {
  const char* scenePath = std::getenv("RCFD_BENCH_CFDDEM_SCENE");
  Scene scene = scenePath ? loadSceneFile(scenePath)
                          : loadSceneText(std::string(embeddedFiles().at("examples/quick.json")), "examples/quick.json");
  if (o.quick) {  // a smoke test in seconds: a tenth of the bed
    scene.process.bed_mass *= 0.1;
    scene.name += "-tenth";
  }
  const double ramp = envOr("RCFD_BENCH_CFDDEM_RAMP", o.quick ? 0.02 : 0.1);
  const double seconds = envOr("RCFD_BENCH_CFDDEM_SECONDS", o.quick ? 0.02 : 0.2);
  CfdDemSimulation sim(scene, 1);
  // The grid is part of the key: a settled state carries the gas fields of its grid.
  const auto& shape = sim.grid().shape;
  const auto cache = std::filesystem::temp_directory_path() /
                     ("rcfd-bench-cfddem-" + scene.name + "-" + std::to_string(shape[0]) + "x" +
                      std::to_string(shape[1]) + "x" + std::to_string(shape[2]) + "-settled.h5");
  const char* startPath = std::getenv("RCFD_BENCH_CFDDEM_START");
  if (startPath) {
    // A developed state replaces fill and ramp: saved by an earlier run with RCFD_BENCH_CFDDEM_SAVE
    // (/state), or a database job's checkpoint.h5 (/simulation).
    h5::File f(startPath, h5::File::Mode::ReadOnly);
    sim.loadState(f, f.exists("/state") ? "/state" : "/simulation");
  } else if (std::filesystem::exists(cache)) {
    h5::File f(cache.string(), h5::File::Mode::ReadOnly);
    sim.loadState(f, "/state");
    std::cerr << "cfddem: settled bed from " << cache << "\n";
  } else {
    const auto t0 = std::chrono::steady_clock::now();
    const FillResult r = sim.fillAndSettle();
    std::cerr << "cfddem: filled " << r.inserted << " parcels in "
              << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() << " s wall\n";
    h5::File f(cache.string(), h5::File::Mode::Create);
    sim.saveState(f, "/state");
  }
  const std::size_t parcels = sim.dem().particles().size();
  const std::int64_t stepsPerSecond = std::llround(1.0 / sim.demTimeStep());
  // Ramp (untimed), as the database job does.
  const std::int64_t rampEnd = sim.demStep() + (startPath ? 0 : std::llround(ramp * stepsPerSecond));
  while (sim.demStep() < rampEnd) {
    const double f = std::min(1.0, 1.0 - double(rampEnd - sim.demStep()) / (ramp * stepsPerSecond));
    sim.setFlowFactor(std::max(0.0, f));
    sim.step(rampEnd);
  }
  sim.setFlowFactor(1.0);
  const std::int64_t start = sim.demStep(), end = start + std::llround(seconds * stepsPerSecond);
  long couplingSteps = 0, pressureIterations = 0;
  double gasWall = 0.0, maxAlphaP = 0.0, maxCourant = 0.0;
  const DemTimings dem0 = sim.dem().timings();
  const double demWall0 = dem0.drift + dem0.build + dem0.pairs + dem0.gather;
  const long builds0 = sim.dem().neighbourList().builds();
  const double cpu0 = cpuSeconds();
  const auto t0 = std::chrono::steady_clock::now();
  const std::int64_t report = std::max<std::int64_t>(1, std::llround(0.05 * stepsPerSecond));
  std::int64_t nextReport = start + report;
  const char* pgm = std::getenv("RCFD_BENCH_CFDDEM_PGM");
  std::ofstream series;  // RCFD_BENCH_CFDDEM_SERIES=path: time, pressure drop, DEM steps per coupling step
  if (const char* path = std::getenv("RCFD_BENCH_CFDDEM_SERIES")) series.open(path);
  while (sim.demStep() < end) {
    sim.step(std::min(end, nextReport));
    if (sim.demStep() == nextReport) {
      std::cerr << "  t = " << sim.time() << " s: wall " << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()
                << " s, k " << sim.lastStep().demSteps << ", Courant " << sim.lastStep().courant << ", max alpha_P "
                << sim.lastStep().maxAlphaP << ", pressure drop " << sim.pressureDrop() << " Pa\n";
      if (pgm && (nextReport - start) % (4 * report) == 0)
        writeAlphaImage(sim, std::string(pgm) + "-" + std::to_string((nextReport - start) / report) + ".pgm");
      nextReport += report;
    }
    ++couplingSteps;
    if (series.is_open()) series << sim.time() << " " << sim.pressureDrop() << " " << sim.lastStep().demSteps << "\n";
    pressureIterations += sim.lastStep().pressureIterations;
    maxAlphaP = std::max(maxAlphaP, sim.lastStep().maxAlphaP);
    maxCourant = std::max(maxCourant, sim.lastStep().courant);
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu = cpuSeconds() - cpu0;
  const double demWall = sim.dem().timings().drift + sim.dem().timings().build + sim.dem().timings().pairs +
                         sim.dem().timings().gather - demWall0;
  gasWall = wall - demWall;
  const double simulated = double(end - start) * sim.demTimeStep();
  const double parcelSteps = double(parcels) * double(end - start);
  nlohmann::json out;
  out["scene"] = scene.name;
  out["parcels"] = parcels;
  out["cells"] = sim.grid().cellCount();
  out["simulated_s"] = simulated;
  out["wall_s"] = wall;
  out["cpu_s"] = cpu;
  out["wall_s_per_simulated_s"] = wall / simulated;
  out["cpu_s_per_simulated_s"] = cpu / simulated;
  out["parcel_steps_per_s"] = parcelSteps / wall;
  out["coupling_steps"] = couplingSteps;
  out["mean_dem_steps_per_gas_step"] = double(end - start) / double(couplingSteps);
  out["mean_pressure_iterations"] = double(pressureIterations) / double(couplingSteps);
  out["dem_wall_share"] = demWall / wall;
  const DemTimings& dem1 = sim.dem().timings();
  out["dem_phase_wall_s"] = {{"kick_and_drift", dem1.drift - dem0.drift},
                             {"neighbour_list", dem1.build - dem0.build},
                             {"pair_forces", dem1.pairs - dem0.pairs},
                             {"gather_walls_kick", dem1.gather - dem0.gather}};
  out["dem_steps_per_neighbour_list_build"] =
      double(end - start) / double(std::max(1L, sim.dem().neighbourList().builds() - builds0));
  out["gas_and_coupling_wall_share"] = gasWall / wall;
  out["max_alpha_p"] = maxAlphaP;
  out["max_courant"] = maxCourant;
  out["pressure_drop_pa"] = sim.pressureDrop();
  std::cerr << "cfddem " << scene.name << ": " << parcels << " parcels, " << simulated << " s simulated in " << wall
            << " s wall (" << cpu << " s CPU): " << wall / simulated << " s wall per simulated s, "
            << parcelSteps / wall << " parcel-steps/s, " << double(end - start) / double(couplingSteps)
            << " DEM steps per gas step, DEM share " << demWall / wall << ", max alpha_P " << maxAlphaP
            << ", pressure drop " << sim.pressureDrop() << " Pa\n";
  if (pgm) writeAlphaImage(sim, std::string(pgm) + "-alpha.pgm");
  if (const char* save = std::getenv("RCFD_BENCH_CFDDEM_SAVE")) {
    h5::File f(save, h5::File::Mode::Create);
    sim.saveState(f, "/state");
  }
  return out;
}

const bool registered = addBenchmark(
    "cfddem", "coupled CFD-DEM of examples/quick.json: wall s per simulated s, parcel-steps/s including the gas",
    runCfdDem);

}  // namespace
}  // namespace rcfd::bench
