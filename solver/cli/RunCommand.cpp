// rcfd-solve run JOB.json --out DIR [--progress-json]: runs one job locally (docs/contracts.md).
#include <omp.h>

#include <iostream>
#include <memory>

#include "cli/Command.hpp"
#include "core/Errors.hpp"
#include "jobs/Cancellation.hpp"
#include "jobs/JobRunner.hpp"

namespace {
/// A cancelled run that has not stopped by itself this long after the signal is ended by the watchdog
/// (jobs/Cancellation.hpp): the server's cancel promises 5 s, and the exit itself needs the rest.
constexpr double kDefaultCancelDeadlineSeconds = 4.0;

const bool registered = rcfd::cli::addCommand(
    "run", "run one job (database, calibration or spray) and write DIR/summary.json, DIR/result.h5",
    [](CLI::App& app) {
      struct Args {
        std::string job, out;
        bool progressJson = false;
        int threads = 0;
        long stopAfter = -1;
        int maxPressureIterations = 0;
        double progressInterval = 1.0;
        double cancelDeadline = kDefaultCancelDeadlineSeconds;
      };
      auto args = std::make_shared<Args>();
      app.add_option("JOB", args->job, "job file (JSON)")->required();
      app.add_option("--out", args->out, "output directory (re-running with the same directory resumes)")
          ->required();
      app.add_flag("--progress-json", args->progressJson, "one JSON progress object per line on stdout");
      app.add_option("--threads", args->threads, "OpenMP threads (default: all cores)");
      app.add_option("--cancel-deadline", args->cancelDeadline,
                     "seconds after SIGINT/SIGTERM after which a run that has not stopped by itself exits 130 "
                     "without a new checkpoint (0: wait for it)")
          ->capture_default_str()
          ->check(CLI::NonNegativeNumber);
      app.add_option("--stop-after-steps", args->stopAfter,
                     "testing: checkpoint and exit 130 after this many steps")
          ->group("");
      app.add_option("--progress-interval", args->progressInterval,
                     "testing: seconds of wall time between progress reports (0: every report)")
          ->group("")
          ->check(CLI::NonNegativeNumber);
      app.add_option("--max-pressure-iterations", args->maxPressureIterations,
                     "testing: cap the gas pressure solver's iterations per step (a solve that does not converge)")
          ->group("");
      return [args] {
        if (args->threads > 0) omp_set_num_threads(args->threads);
        rcfd::installCancellationHandlers();
        if (args->cancelDeadline > 0.0) rcfd::startCancellationWatchdog(args->cancelDeadline);
        const rcfd::JobSpec job = rcfd::loadJobFile(args->job);
        rcfd::RunOptions options;
        options.outDir = args->out;
        options.progressJson = args->progressJson;
        options.progressInterval = args->progressInterval;
        options.stopAfterSteps = args->stopAfter;
        options.maxPressureIterations = args->maxPressureIterations;
        const auto summary = rcfd::runJob(job, options);
        std::cerr << "done: " << args->out << "/summary.json (" << summary.value("wall_time_s", 0.0)
                  << " s)\n";
        return rcfd::exit_code::success;
      };
    });
}  // namespace
