// rcfd-bench: runs one registered benchmark (bench/BenchRegistry.hpp).
#include <CLI/CLI.hpp>
#include <iostream>
#include <map>
#include <omp.h>

#include "BenchRegistry.hpp"

namespace rcfd::bench {
namespace {
struct Entry {
  std::string description;
  Benchmark run;
};
std::map<std::string, Entry>& registry() {
  static std::map<std::string, Entry> instance;
  return instance;
}
}  // namespace
bool addBenchmark(std::string name, std::string description, Benchmark run) {
  registry().emplace(std::move(name), Entry{std::move(description), std::move(run)});
  return true;
}
}  // namespace rcfd::bench

int main(int argc, char** argv) {
  using namespace rcfd::bench;
  CLI::App app{"rcfd-bench: speed and accuracy-versus-time benchmarks"};
  std::string name;
  Options options;
  bool json = false;
  std::string names;
  for (const auto& [n, e] : registry()) names += "\n  " + n + ": " + e.description;
  app.add_option("NAME", name, "benchmark to run:" + names)->required();
  app.add_flag("--quick", options.quick, "reduced size (seconds)");
  app.add_flag("--json", json, "print the figures as one JSON object on the last line");
  app.add_option("--threads", options.threads, "OpenMP threads (default: all)");
  CLI11_PARSE(app, argc, argv);
  auto it = registry().find(name);
  if (it == registry().end()) {
    std::cerr << "unknown benchmark \"" << name << "\"; valid names are:" << names << "\n";
    return 2;
  }
  if (options.threads > 0) omp_set_num_threads(options.threads);
  nlohmann::json result = it->second.run(options);
  result["benchmark"] = name;
  result["threads"] = options.threads > 0 ? options.threads : omp_get_max_threads();
  result["quick"] = options.quick;
  if (json) std::cout << result.dump() << std::endl;
  else std::cout << result.dump(2) << std::endl;
  return 0;
}
