// rcfd-bench tracers: the tracer step at paper scale -- 472,850 tracers in the ProCell apparatus on a
// grid of about 73,647 cells, synthetic pseudo-periodic fields (a swaying spout), effects transport +
// fluctuation + walls + tracer_volume_fraction. Also the cost of each effect added on its own.
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <numbers>

#include "BenchRegistry.hpp"
#include "fields/AnalyticDatabase.hpp"
#include "geometry/Apparatus.hpp"
#include "tracers/TracerSimulation.hpp"

namespace rcfd::bench {
namespace {

/// A spout that sways left and right with period 0.5 s, an annulus sliding down the V walls.
void swayingSpout(const CartesianGrid& grid, int, double t, FieldFrame& f) {
  const double centre = 0.02 * std::sin(2 * std::numbers::pi * t / 0.5);
  for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
    const auto ijk = grid.cellIjk(c);
    const auto p = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
    const double dx = p.x() - centre;
    const bool spout = std::abs(dx) < 0.02 && p.y() < 0.3;
    const bool bed = p.y() < 0.15;
    f.alpha_p[std::size_t(c)] = float(spout ? 0.1 : (bed ? 0.55 : 0.01));
    f.u_p[3 * c] = float(spout ? 0.2 * dx / 0.02 : (bed ? -0.1 * std::copysign(1.0, dx) : 0.0));
    f.u_p[3 * c + 1] = float(spout ? 2.5 : (bed ? -0.15 : -1.0));
    f.u_g[3 * c + 1] = float(spout ? 12.0 : 2.0);
  }
}

struct Timing {
  double secondsPerStep = 0.0;
  double tracerStepsPerSecond = 0.0;
  double cpuSecondsPerStep = 0.0;  ///< process CPU time (all threads) per step: what the load distorts least
  double substepFraction = 0.0;    ///< extra sub-steps per tracer-step (last step)
  double wallHitFraction = 0.0;    ///< reflections per tracer-step (last step)
};

double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

Timing timeRun(const Scene& scene, std::shared_ptr<FieldDatabase> db, int steps) {
  RecurrencePath path;
  for (int k = 0; k < steps + 2; ++k) path.frames.push_back(k % db->frameCount());
  TracerSimulation sim(scene, db, path, {1, steps, 0});
  sim.step();  // warm caches and first-touch pages outside the timing
  const double cpu0 = processCpuSeconds();
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 1; k < steps; ++k) sim.step();
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  Timing t;
  t.secondsPerStep = s / (steps - 1);
  t.cpuSecondsPerStep = (processCpuSeconds() - cpu0) / (steps - 1);
  t.tracerStepsPerSecond = double(scene.rcfd.tracers) / t.secondsPerStep;
  t.substepFraction = double(sim.motionStatistics().substeps) / double(scene.rcfd.tracers);
  t.wallHitFraction = double(sim.motionStatistics().wallHits) / double(scene.rcfd.tracers);
  return t;
}

nlohmann::json runTracers(const Options& options) {
  Scene scene;  // ProCell defaults: 250 x 600 x 200 mm
  const double cell = options.quick ? 0.015 : 0.0074;  // 0.0074 m -> about 74k cells
  scene.grid.cell_size = Vec3(cell, cell, cell);
  scene.rcfd.tracers = options.quick ? 47285 : 472850;
  scene.rcfd.d0 = 5e-4;
  Apparatus apparatus(scene.apparatus);
  const CartesianGrid grid = makeGrid(apparatus, scene.grid);
  const auto open = openFractions(apparatus, grid);
  const std::vector<float> fluid(open.begin(), open.end());
  const int frames = options.quick ? 10 : 100;
  std::cerr << "grid " << grid.shape[0] << " x " << grid.shape[1] << " x " << grid.shape[2] << " = "
            << grid.cellCount() << " cells, " << scene.rcfd.tracers << " tracers, " << frames << " frames\n";
  auto db = makeAnalyticDatabase(grid, fluid, scene.rcfd.dt, frames,
                                 [&](int n, double t, FieldFrame& f) { swayingSpout(grid, n, t, f); });
  const int steps = options.quick ? 6 : 41;

  scene.effects = {"transport", "walls", "fluctuation", "tracer_volume_fraction"};
  const Timing headline = timeRun(scene, db, steps);
  std::cerr << "transport+fluctuation+walls+tracer_volume_fraction: " << headline.tracerStepsPerSecond
            << " tracer-steps/s (" << headline.secondsPerStep * 1e3 << " ms/step, "
            << headline.cpuSecondsPerStep * 1e3 << " CPU-ms/step, "
            << headline.cpuSecondsPerStep / double(scene.rcfd.tracers) * 1e9 << " CPU-ns/tracer-step; "
            << headline.substepFraction << " extra sub-steps and " << headline.wallHitFraction
            << " reflections per tracer-step)\n";

  nlohmann::json costs = nlohmann::json::object();
  const std::vector<std::pair<std::string, std::vector<std::string>>> variants = {
      {"transport+walls", {"transport", "walls"}},
      {"+tracer_volume_fraction", {"transport", "walls", "tracer_volume_fraction"}},
      {"+free_flight", {"transport", "walls", "fluctuation", "tracer_volume_fraction", "free_flight"}},
      {"+residence_time", {"transport", "walls", "fluctuation", "tracer_volume_fraction", "residence_time"}},
      {"+field_average", {"transport", "walls", "fluctuation", "tracer_volume_fraction", "field_average"}},
  };
  // RCFD_BENCH_TRACERS_HEADLINE_ONLY=1: the headline configuration only (A/B comparisons of the kernel).
  const char* headlineOnly = std::getenv("RCFD_BENCH_TRACERS_HEADLINE_ONLY");
  for (const auto& [label, effects] : variants) {
    if (headlineOnly && std::string(headlineOnly) == "1") break;
    scene.effects = effects;
    const Timing t = timeRun(scene, db, steps);
    costs[label] = {{"ms_per_step", t.secondsPerStep * 1e3},
                    {"cpu_ms_per_step", t.cpuSecondsPerStep * 1e3},
                    {"tracer_steps_per_s", t.tracerStepsPerSecond}};
    std::cerr << label << ": " << t.secondsPerStep * 1e3 << " ms/step, " << t.cpuSecondsPerStep * 1e3
              << " CPU-ms/step\n";
  }
  return {{"tracer_steps_per_s", headline.tracerStepsPerSecond},
          {"ms_per_step", headline.secondsPerStep * 1e3},
          {"cpu_ms_per_step", headline.cpuSecondsPerStep * 1e3},
          {"cpu_ns_per_tracer_step", headline.cpuSecondsPerStep / double(scene.rcfd.tracers) * 1e9},
          {"tracer_steps_per_cpu_s", double(scene.rcfd.tracers) / headline.cpuSecondsPerStep},
          {"tracers", scene.rcfd.tracers},
          {"cells", grid.cellCount()},
          {"effect_costs", costs}};
}

const bool registered = addBenchmark("tracers", "tracer step at paper scale (472,850 tracers, ~74k cells)", runTracers);

}  // namespace
}  // namespace rcfd::bench
