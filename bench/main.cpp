// rcfd-bench: runs one registered benchmark (bench/BenchRegistry.hpp).
#include <CLI/CLI.hpp>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <omp.h>
#include <string>
#include <vector>

#include "BenchRegistry.hpp"
#include "core/Isa.hpp"

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
/// The CPU as /proc/cpuinfo names it, with its family and model numbers ("AMD EPYC (family 25, model
/// 1)"), or "unknown": this project's VMs have been AVX-512 Zen 5s (family 26), AVX2 Zen 3s
/// (family 25), both "AMD EPYC", and an AVX-512 Emerald Rapids ("Intel Xeon", family 6, model 207),
/// whose figures differ by up to 2x, so every result says which.
std::string cpuName() {
  std::ifstream in("/proc/cpuinfo");
  std::string name = "unknown", family = "?", model = "?";
  auto value = [](const std::string& line) {
    const auto colon = line.find(':');
    const auto start = colon == std::string::npos ? std::string::npos : line.find_first_not_of(' ', colon + 1);
    return start == std::string::npos ? std::string() : line.substr(start);
  };
  for (std::string line; std::getline(in, line) && !line.empty();) {  // the first processor only
    if (line.rfind("model name", 0) == 0) name = value(line);
    else if (line.rfind("cpu family", 0) == 0) family = value(line);
    else if (line.rfind("model", 0) == 0 && line.rfind("model name", 0) != 0) model = value(line);
  }
  return name + " (family " + family + ", model " + model + ")";
}

/// The widest vector instructions the hot kernels run: the variant a portable build picked
/// (core/Isa.hpp), or what a native build was compiled for.
const char* vectorIsa() {
  if (kernelIsa() != Isa::native) return isaName(kernelIsa());
#if defined(__AVX512F__)
  return "avx512";
#elif defined(__AVX2__)
  return "avx2";
#elif defined(__SSE2__)
  return "sse2";
#else
  return "scalar";
#endif
}

/// "portable" (kernel variants picked at run time) or "native" (-DRCFD_NATIVE=ON)
const char* buildKind() { return builtIsas() == std::vector<Isa>{Isa::native} ? "native" : "portable"; }

/// OMP_WAIT_POLICY as set, or "default" (libgomp spins a while before it sleeps, as the server and
/// rcfd-solve run): on 2 threads a passive wait costs 0.4-0.5 ms per spray step, 7-10% of it, so a
/// figure means little without it.
std::string waitPolicy() {
  const char* policy = std::getenv("OMP_WAIT_POLICY");
  return policy && *policy ? policy : "default";
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
  result["cpu"] = cpuName();
  result["vector_isa"] = vectorIsa();
  result["build"] = rcfd::bench::buildKind();
  result["omp_wait_policy"] = waitPolicy();
  result["quick"] = options.quick;
  if (json) std::cout << result.dump() << std::endl;
  else std::cout << result.dump(2) << std::endl;
  return 0;
}
