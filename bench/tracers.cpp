// rcfd-bench tracers: the tracer step at paper scale -- 472,850 tracers in the ProCell apparatus on a
// grid of about 73,647 cells, synthetic pseudo-periodic fields (a swaying spout), effects transport +
// fluctuation + walls + tracer_volume_fraction. Also the cost of each effect added on its own, and of
// the Euler integrator. Environment, for A/B runs: RCFD_BENCH_TRACERS_HEADLINE_ONLY=1 (headline only),
// RCFD_BENCH_INTEGRATOR and RCFD_BENCH_EFFECTS=a,b,.. (override the headline's),
// RCFD_BENCH_SORT_INTERVAL=N (tracers sorted by cell every N steps, 0 never), RCFD_BENCH_STEPS,
// RCFD_BENCH_SCALAR_KERNEL=1 (no block path).
#include <cstdlib>
#include <iostream>

#include "TracerBenchCase.hpp"

namespace rcfd::bench {
namespace {

nlohmann::json runTracers(const Options& options) {
  TracerBenchCase bench(options);
  Scene& scene = bench.scene;
  auto db = bench.db;
  // 100 timed steps after one untimed: one whole interval of the tracers' sort by cell (default 100
  // steps), so the figure includes the sort and the order's decay after it. RCFD_BENCH_STEPS overrides.
  const char* stepsOverride = std::getenv("RCFD_BENCH_STEPS");
  const int steps = stepsOverride ? std::atoi(stepsOverride) : (options.quick ? 5 : 100);

  scene.effects = {"transport", "walls", "fluctuation", "tracer_volume_fraction"};
  if (const char* e = std::getenv("RCFD_BENCH_INTEGRATOR")) scene.rcfd.integrator = e;
  if (const char* e = std::getenv("RCFD_BENCH_MAX_COURANT")) scene.rcfd.max_courant = std::atof(e);
  if (const char* e = std::getenv("RCFD_BENCH_EFFECTS")) {
    scene.effects.clear();
    std::string s(e);
    for (std::size_t a = 0, b; a < s.size(); a = b + 1) {
      b = s.find(',', a);
      if (b == std::string::npos) b = s.size();
      scene.effects.push_back(s.substr(a, b - a));
    }
  }
  const Timing headline = timeRun(scene, db, 1, steps);
  std::cerr << "transport+fluctuation+walls+tracer_volume_fraction: " << headline.tracerStepsPerSecond
            << " tracer-steps/s (" << headline.secondsPerStep * 1e3 << " ms/step, "
            << headline.cpuSecondsPerStep * 1e3 << " CPU-ms/step, "
            << headline.cpuSecondsPerStep / double(scene.rcfd.tracers) * 1e9 << " CPU-ns/tracer-step; "
            << headline.substepFraction << " extra sub-steps and " << headline.wallHitFraction
            << " reflections per tracer-step, " << headline.scalarFraction << " on the scalar path, "
            << headline.wallTestFraction << " exact wall tests)\n";
  std::cerr << "  stages, ms per step:";
  for (const auto& [stage, ms] : headline.stageMsPerStep.items()) std::cerr << " " << stage << " " << ms.get<double>();
  std::cerr << "\n";

  nlohmann::json costs = nlohmann::json::object();
  const std::vector<std::pair<std::string, std::vector<std::string>>> variants = {
      {"transport+walls", {"transport", "walls"}},
      {"+tracer_volume_fraction", {"transport", "walls", "tracer_volume_fraction"}},
      {"+free_flight", {"transport", "walls", "fluctuation", "tracer_volume_fraction", "free_flight"}},
      {"+residence_time", {"transport", "walls", "fluctuation", "tracer_volume_fraction", "residence_time"}},
      {"+field_average", {"transport", "walls", "fluctuation", "tracer_volume_fraction", "field_average"}},
      {"directed_relaxation for fluctuation", {"transport", "walls", "directed_relaxation", "tracer_volume_fraction"}},
      {"headline, euler", {"transport", "walls", "fluctuation", "tracer_volume_fraction"}},
  };
  // RCFD_BENCH_TRACERS_HEADLINE_ONLY=1: the headline configuration only (A/B comparisons of the kernel).
  const char* headlineOnly = std::getenv("RCFD_BENCH_TRACERS_HEADLINE_ONLY");
  for (const auto& [label, effects] : variants) {
    if (headlineOnly && std::string(headlineOnly) == "1") break;
    scene.effects = effects;
    // The integrator is an accuracy knob: Euler samples u_P once per sub-step instead of twice.
    Scene variant = scene;
    if (label.find("euler") != std::string::npos) variant.rcfd.integrator = "euler";
    const Timing t = timeRun(variant, db, 1, steps);
    costs[label] = {{"ms_per_step", t.secondsPerStep * 1e3},
                    {"cpu_ms_per_step", t.cpuSecondsPerStep * 1e3},
                    {"tracer_steps_per_s", t.tracerStepsPerSecond},
                    {"free_flight_fraction", t.freeFlightFraction},
                    {"stage_ms_per_step", t.stageMsPerStep}};
    std::cerr << label << ": " << t.secondsPerStep * 1e3 << " ms/step, " << t.cpuSecondsPerStep * 1e3
              << " CPU-ms/step";
    if (t.freeFlightFraction > 0.0) std::cerr << " (" << t.freeFlightFraction << " of the tracers in free flight)";
    std::cerr << "\n";
  }
  return {{"tracer_steps_per_s", headline.tracerStepsPerSecond},
          {"ms_per_step", headline.secondsPerStep * 1e3},
          {"cpu_ms_per_step", headline.cpuSecondsPerStep * 1e3},
          {"cpu_ns_per_tracer_step", headline.cpuSecondsPerStep / double(scene.rcfd.tracers) * 1e9},
          {"tracer_steps_per_cpu_s", double(scene.rcfd.tracers) / headline.cpuSecondsPerStep},
          {"tracers", scene.rcfd.tracers},
          {"scalar_path_fraction", headline.scalarFraction},
          {"exact_wall_test_fraction", headline.wallTestFraction},
          {"substep_fraction", headline.substepFraction},
          {"cells", bench.cells},
          {"field", bench.field},
          {"field_statistics", bench.statistics},
          {"tracer_spread", headline.tracerSpread},
          {"stage_ms_per_step", headline.stageMsPerStep},
          {"effect_costs", costs}};
}

const bool registered = addBenchmark("tracers", "tracer step at paper scale (472,850 tracers, ~74k cells)", runTracers);

}  // namespace
}  // namespace rcfd::bench
