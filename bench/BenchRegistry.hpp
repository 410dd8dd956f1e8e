#pragma once
/// \file BenchRegistry.hpp
/// rcfd-bench NAME [--quick] [--json] [--threads N]: each bench/*.cpp registers one named benchmark.
/// A benchmark prints human-readable lines as it goes and returns its figures as a JSON object; with
/// --json, main prints that object as the last line of stdout, with "benchmark", "threads", "cpu",
/// "vector_isa" and "omp_wait_policy" added (docs/contracts.md, "Benchmark output": tracers ->
/// tracer_steps_per_s, spray -> sim_seconds_per_wall_second, dem -> particle_steps_per_s, recurrence ->
/// matrix_seconds, accuracy -> document).

#include <functional>
#include <nlohmann/json.hpp>
#include <string>

namespace rcfd::bench {

struct Options {
  bool quick = false;  ///< a reduced size that runs in seconds (smoke test, CI)
  int threads = 0;     ///< OpenMP threads (0: the OpenMP default)
};

using Benchmark = std::function<nlohmann::json(const Options&)>;

bool addBenchmark(std::string name, std::string description, Benchmark run);

}  // namespace rcfd::bench
