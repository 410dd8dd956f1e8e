// rcfd-solve coverage-figure RESULT.h5... --out FILE.svg [--label NAME]... [--bins N]: the coverage
// distributions of several spray jobs in one figure (analysis/CoverageFigure.hpp), the paper's Fig. 12
// for the beds with and without draft plates. Prints each run's statistics as JSON.

#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "analysis/CoverageFigure.hpp"
#include "cli/Command.hpp"
#include "core/Errors.hpp"

namespace rcfd::cli {
namespace {

struct Options {
  std::vector<std::string> results;
  std::vector<std::string> labels;
  std::string out;
  int bins = 40;
};

int run(const Options& o) {
  if (!o.labels.empty() && o.labels.size() != o.results.size())
    throw InputError("command line", "--label",
                     std::to_string(o.labels.size()) + " labels for " + std::to_string(o.results.size()) +
                         " result files: give one per file, or none");
  std::vector<analysis::CoverageRun> runs;
  for (std::size_t k = 0; k < o.results.size(); ++k)
    runs.push_back({o.labels.empty() ? std::filesystem::path(o.results[k]).parent_path().filename().string()
                                     : o.labels[k],
                    analysis::readTracerCoverage(o.results[k])});
  const auto parent = std::filesystem::path(o.out).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  const auto d = analysis::writeCoverageFigure(runs, o.bins, o.out);
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t k = 0; k < runs.size(); ++k)
    out.push_back({{"label", runs[k].label}, {"file", o.results[k]}, {"tracers", runs[k].coverage.size()},
                   {"mean", d[k].mean}, {"median", d[k].median}, {"p10", d[k].p10}, {"p90", d[k].p90}});
  std::cout << out.dump(2) << "\n";
  return exit_code::success;
}

const bool registered = addCommand(
    "coverage-figure", "the coverage distributions of several spray jobs in one figure (the paper's Fig. 12)",
    [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("RESULT", o->results, "a spray job's result.h5 (one or more)")->required();
      app.add_option("--out", o->out, "the SVG file to write")->required();
      app.add_option("--label", o->labels, "a name per result file, in their order (default: its directory)");
      app.add_option("--bins", o->bins, "histogram bins over the values' range (default 40)")
          ->check(CLI::Range(1, 1000));
      return [o] { return run(*o); };
    });

}  // namespace
}  // namespace rcfd::cli
