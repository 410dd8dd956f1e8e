#pragma once
// The paper-scale tracer case shared by `rcfd-bench tracers` and `rcfd-bench spray`: the ProCell
// apparatus (250 x 600 x 200 mm) on 7.4 mm cells (34 x 81 x 27 = 74,358 cells, the paper's 73,647
// within 1%), 472,850 tracers, 100 in-memory frames of a circulating spouted bed (CirculatingBed.hpp;
// RCFD_BENCH_FIELD=swaying_spout selects the swaying spout of SyntheticFields.hpp, a field that
// gathers the tracers into a few cells), dt = dt_rec = 5 ms.
// --quick: 15 mm cells, 47,285 tracers, 10 frames.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "BenchRegistry.hpp"
#include "CirculatingBed.hpp"
#include "SyntheticFields.hpp"
#include "fields/AnalyticDatabase.hpp"
#include "geometry/Apparatus.hpp"
#include "tracers/TracerSimulation.hpp"

namespace rcfd::bench {

inline double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// What makes a field database costly to move tracers through, weighted by solids volume (alpha_P x
/// open volume) over all frames: the fraction of the solids moving more than one cell per step (they
/// need sub-steps), faster than 1 m/s, their mean speed, and the fractions in dense (alpha_P > 0.45)
/// and dilute (alpha_P < 0.2) cells. For comparison, the quick example's CFD-DEM database:
/// 0.074, 0.187, 0.58 m/s, 0.33 and 0.40; the circulating bed 0.075, 0.135, 0.57, 0.29 and 0.38.
inline nlohmann::json fieldStatistics(const FieldDatabase& db, double dt) {
  const CartesianGrid& g = db.grid();
  const double oneCellPerStep = g.spacing.minCoeff() / dt;
  double solids = 0.0, fast = 0.0, overOne = 0.0, speed = 0.0, dense = 0.0, dilute = 0.0;
  for (int n = 0; n < db.frameCount(); ++n) {
    const auto f = db.frame(n);
    for (std::size_t c = 0; c < std::size_t(g.cellCount()); ++c) {
      const double a = f->alpha_p[c], w = a * double(db.fluidFraction()[c]);
      const double u = std::sqrt(double(f->u_p[3 * c]) * f->u_p[3 * c] + double(f->u_p[3 * c + 1]) * f->u_p[3 * c + 1] +
                                 double(f->u_p[3 * c + 2]) * f->u_p[3 * c + 2]);
      solids += w, speed += w * u;
      if (u > oneCellPerStep) fast += w;
      if (u > 1.0) overOne += w;
      if (a > 0.45) dense += w;
      if (a < 0.2) dilute += w;
    }
  }
  if (!(solids > 0.0)) return nlohmann::json::object();
  return {{"solids_over_one_cell_per_step", fast / solids}, {"solids_over_1_m_per_s", overOne / solids},
          {"mean_solids_speed", speed / solids}, {"solids_in_alpha_over_0.45", dense / solids},
          {"solids_in_alpha_under_0.2", dilute / solids}};
}

struct TracerBenchCase {
  Scene scene;  // ProCell defaults
  std::shared_ptr<FieldDatabase> db;
  std::int64_t cells = 0;
  std::string field;          ///< circulating_bed or swaying_spout (RCFD_BENCH_FIELD)
  nlohmann::json statistics;  ///< fieldStatistics() of the database

  /// RCFD_BENCH_FIELD, or circulating_bed.
  static std::string fieldFromEnvironment() {
    const char* e = std::getenv("RCFD_BENCH_FIELD");
    return e ? std::string(e) : std::string("circulating_bed");
  }

  explicit TracerBenchCase(const Options& options, std::string fieldName = fieldFromEnvironment())
      : field(std::move(fieldName)) {
    const double cell = options.quick ? 0.015 : 0.0074;  // 0.0074 m -> about 74k cells
    scene.grid.cell_size = Vec3(cell, cell, cell);
    scene.rcfd.tracers = options.quick ? 47285 : 472850;
    // The tracer count is an accuracy knob: RCFD_BENCH_TRACERS prices other counts on the same case.
    if (const char* e = std::getenv("RCFD_BENCH_TRACERS")) scene.rcfd.tracers = std::atoll(e);
    scene.rcfd.d0 = 5e-4;
    // RCFD_BENCH_VELOCITY_INTERPOLATION=mass_weighted prices the mass-weighted u_P^rec on the same case.
    if (const char* e = std::getenv("RCFD_BENCH_VELOCITY_INTERPOLATION")) scene.rcfd.velocity_interpolation = e;
    Apparatus apparatus(scene.apparatus);
    const CartesianGrid grid = makeGrid(apparatus, scene.grid);
    const auto open = openFractions(apparatus, grid);
    const std::vector<float> fluid(open.begin(), open.end());
    const int frames = options.quick ? 10 : 100;
    cells = grid.cellCount();
    std::cerr << "grid " << grid.shape[0] << " x " << grid.shape[1] << " x " << grid.shape[2] << " = "
              << grid.cellCount() << " cells, " << scene.rcfd.tracers << " tracers, " << frames << " frames\n";
    if (field == "swaying_spout") {
      db = makeAnalyticDatabase(grid, fluid, scene.rcfd.dt, frames,
                                [&](int n, double t, FieldFrame& f) { swayingSpout(grid, n, t, f); });
    } else if (field == "circulating_bed") {
      const CirculatingBed bed(scene, grid, fluid);
      std::cerr << "circulating bed: bed height " << bed.bedHeight() << " m\n";
      db = makeAnalyticDatabase(grid, fluid, scene.rcfd.dt, frames,
                                [&](int n, double t, FieldFrame& f) { bed(n, t, f); });
    } else {
      throw std::invalid_argument("RCFD_BENCH_FIELD: '" + field + "' is neither circulating_bed nor swaying_spout");
    }
    statistics = fieldStatistics(*db, scene.rcfd.dt);
    std::cerr << field << ": " << statistics.dump() << "\n";
  }
};

/// Wall and CPU time of `steps` steps after `warmup` untimed ones (at least one: first-touch pages).
struct Timing {
  double secondsPerStep = 0.0;
  double tracerStepsPerSecond = 0.0;
  double cpuSecondsPerStep = 0.0;  ///< process CPU time (all threads) per step: what the load distorts least
  double substepFraction = 0.0;    ///< extra sub-steps per tracer-step (mean over the timed steps)
  double wallHitFraction = 0.0;    ///< reflections per tracer-step (mean)
  double scalarFraction = 0.0;     ///< tracer-steps on the kernel's scalar path (mean)
  double wallTestFraction = 0.0;   ///< block-path sub-steps that needed the exact wall test, per tracer-step (mean)
  double freeFlightFraction = 0.0; ///< tracer-steps in free flight (mean)
  nlohmann::json stageMsPerStep = nlohmann::json::object();  ///< TracerSimulation::stageSeconds() per step [ms]
  /// How the tracers are spread at the end (cells occupied, alpha_P of the tracers): a case whose
  /// tracers collapse into a few cells times a kernel that reads the same few cells (see CirculatingBed).
  nlohmann::json tracerSpread = nlohmann::json::object();
};

/// Cells holding tracers, the tracers' alpha_P per cell (median, 90th and 99th percentile by tracer,
/// maximum) and the fraction of the tracers in cells above alpha_P 1, at the start of the simulation's
/// last step; empty without `tracer_volume_fraction`. (The 99th percentile sits in cut cells at the
/// walls, where a few tracers in a small open volume make a large alpha_P.)
inline nlohmann::json tracerSpread(const TracerContext& ctx) {
  if (ctx.tracerCount.empty() || ctx.tracerAlpha.size() != ctx.tracerCount.size()) return nlohmann::json::object();
  std::vector<std::pair<float, std::int32_t>> occupied;  // (alpha_P of the tracers, tracers) per occupied cell
  for (std::size_t c = 0; c < ctx.tracerCount.size(); ++c) {
    if (ctx.tracerCount[c] > 0) occupied.emplace_back(ctx.tracerAlpha[c], ctx.tracerCount[c]);
  }
  if (occupied.empty()) return nlohmann::json::object();
  std::sort(occupied.begin(), occupied.end());
  std::int64_t total = 0, overOne = 0;
  for (const auto& o : occupied) total += o.second, overOne += o.first > 1.0f ? o.second : 0;
  auto percentile = [&](double q) {
    std::int64_t below = 0;
    for (const auto& o : occupied) {
      below += o.second;
      if (double(below) >= q * double(total)) return o.first;
    }
    return occupied.back().first;
  };
  return {{"occupied_cells", occupied.size()},        {"tracer_alpha_p50", percentile(0.5)},
          {"tracer_alpha_p90", percentile(0.9)},      {"tracer_alpha_p99", percentile(0.99)},
          {"tracer_alpha_max", occupied.back().first}, {"tracers_over_alpha_1", double(overOne) / double(total)}};
}

/// One benchmark simulation, stepped and timed one step at a time (so that two configurations can be
/// timed in alternation, step by step: the VM's speed drifts by up to 30% within minutes, and drift
/// then falls on both alike).
class TimedRun {
 public:
  TimedRun(const Scene& scene, std::shared_ptr<FieldDatabase> db, int warmup, int steps)
      : tracers_(scene.rcfd.tracers), sim_(scene, db, pathFor(*db, warmup + steps), settingsFor(warmup + steps)) {
    for (int k = 0; k < std::max(1, warmup); ++k) sim_.step();
    sim_.resetStageSeconds();
  }

  /// One timed step.
  void step() {
    const double cpu0 = processCpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    sim_.step();
    wall_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    cpu_ += processCpuSeconds() - cpu0;
    ++steps_;
    const MotionStatistics& m = sim_.motionStatistics();
    sum_.substeps += m.substeps, sum_.wallHits += m.wallHits, sum_.scalarPath += m.scalarPath;
    sum_.exactWallTests += m.exactWallTests, sum_.freeFlight += m.freeFlight;
  }

  /// The figures of the timed steps.
  Timing timing() const {
    Timing t;
    const int steps = std::max(1, steps_);
    t.secondsPerStep = wall_ / steps;
    t.cpuSecondsPerStep = cpu_ / steps;
    t.tracerStepsPerSecond = double(tracers_) / t.secondsPerStep;
    const double tracerSteps = double(tracers_) * double(steps);
    t.substepFraction = double(sum_.substeps) / tracerSteps;
    t.wallHitFraction = double(sum_.wallHits) / tracerSteps;
    t.scalarFraction = double(sum_.scalarPath) / tracerSteps;
    t.wallTestFraction = double(sum_.exactWallTests) / tracerSteps;
    t.freeFlightFraction = double(sum_.freeFlight) / tracerSteps;
    for (const auto& [stage, seconds] : sim_.stageSeconds()) t.stageMsPerStep[stage] = seconds / steps * 1e3;
    t.tracerSpread = tracerSpread(std::as_const(sim_).context());
    return t;
  }

  TracerSimulation& simulation() { return sim_; }

 private:
  static RecurrencePath pathFor(const FieldDatabase& db, int steps) {
    RecurrencePath path;
    for (int k = 0; k < steps + 2; ++k) path.frames.push_back(k % db.frameCount());
    return path;
  }
  static TracerRunSettings settingsFor(int steps) {
    // RCFD_BENCH_SCALAR_KERNEL=1: every tracer through the kernel's scalar path (what the block path saves).
    const char* scalarOnly = std::getenv("RCFD_BENCH_SCALAR_KERNEL");
    const bool vectorised = !(scalarOnly && std::string(scalarOnly) == "1");
    // RCFD_BENCH_SORT_INTERVAL=N: tracers re-sorted by cell every N steps (0: never; default 100).
    TracerRunSettings settings{1, steps, 0, vectorised};
    if (const char* e = std::getenv("RCFD_BENCH_SORT_INTERVAL")) settings.sortInterval = std::atoll(e);
    return settings;
  }

  long tracers_;
  TracerSimulation sim_;
  double wall_ = 0.0, cpu_ = 0.0;
  int steps_ = 0;
  MotionStatistics sum_;  // over the timed steps (the field's phases differ in how much sub-stepping they need)
};

/// Wall and CPU time of `steps` steps of one configuration after `warmup` untimed ones.
template <class AfterRun = void (*)(TracerSimulation&)>
Timing timeRun(const Scene& scene, std::shared_ptr<FieldDatabase> db, int warmup, int steps,
               AfterRun after = [](TracerSimulation&) {}) {
  TimedRun run(scene, std::move(db), warmup, steps);
  for (int k = 0; k < steps; ++k) run.step();
  after(run.simulation());
  return run.timing();
}

}  // namespace rcfd::bench
