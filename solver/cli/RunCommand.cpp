// rcfd-solve run JOB.json --out DIR [--progress-json]: runs one job locally (CONTRACTS.md).
#include <omp.h>

#include <iostream>
#include <memory>

#include "cli/Command.hpp"
#include "core/Errors.hpp"
#include "jobs/Cancellation.hpp"
#include "jobs/JobRunner.hpp"

namespace {
const bool registered = rcfd::cli::addCommand(
    "run", "run one job (database, calibration or spray) and write DIR/summary.json, DIR/result.h5",
    [](CLI::App& app) {
      struct Args {
        std::string job, out;
        bool progressJson = false;
        int threads = 0;
        long stopAfter = -1;
      };
      auto args = std::make_shared<Args>();
      app.add_option("JOB", args->job, "job file (JSON)")->required();
      app.add_option("--out", args->out, "output directory (re-running with the same directory resumes)")
          ->required();
      app.add_flag("--progress-json", args->progressJson, "one JSON progress object per line on stdout");
      app.add_option("--threads", args->threads, "OpenMP threads (default: all cores)");
      app.add_option("--stop-after-steps", args->stopAfter,
                     "testing: checkpoint and exit 130 after this many steps")
          ->group("");
      return [args] {
        if (args->threads > 0) omp_set_num_threads(args->threads);
        rcfd::installCancellationHandlers();
        const rcfd::JobSpec job = rcfd::loadJobFile(args->job);
        rcfd::RunOptions options;
        options.outDir = args->out;
        options.progressJson = args->progressJson;
        options.stopAfterSteps = args->stopAfter;
        const auto summary = rcfd::runJob(job, options);
        std::cerr << "done: " << args->out << "/summary.json (" << summary.value("wall_time_s", 0.0)
                  << " s)\n";
        return rcfd::exit_code::success;
      };
    });
}  // namespace
