// The `import` job kind: an OpenFOAM case (the job's `case_dir`, optional `times` "A:B" and `cloud`)
// mapped onto the scene's grid as DIR/database.h5 with its /reference/ series (import/OpenFoamImport.hpp,
// docs/import.md). Writes DIR/result.h5 (/scene, /fields/alpha_p_mean as the database job does) and
// summary.json. Nothing to resume from: a cancelled import removes its partial database and starts
// over when run again. Phase: "import".

#include <filesystem>

#include "analysis/DatabaseFigures.hpp"
#include "cfddem/ReferenceRecorder.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "fields/FieldDatabase.hpp"
#include "import/OpenFoamImport.hpp"
#include "jobs/Cancellation.hpp"
#include "jobs/JobRunner.hpp"
#include "jobs/JobSupport.hpp"
#include "jobs/Progress.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd {
namespace {
namespace fs = std::filesystem;

class ImportJob final : public JobRunner {
 public:
  nlohmann::json run(const JobSpec& job, const RunOptions& options) override {
    const nlohmann::json& doc = job.source;
    openfoam::ImportOptions io;
    io.caseDir = doc.at("case_dir").get<std::string>();
    io.cloud = doc.value("cloud", std::string());
    if (doc.contains("times")) io.times = openfoam::TimeRange::parse(doc.at("times").get<std::string>(), "/times");
    io.databasePath = options.outDir + "/database.h5";
    io.velocitySpread = TracerEffectRegistry::needsVelocitySpread(job.scene.effects);
    ProgressReporter progress(options.progressJson, options.progressInterval, "import ");
    progress.setPhase("import");
    progress.setPhaseFraction(0.0);
    progress.report(0.0, 0.0, true);
    io.progress = [&](double f) {
      progress.setPhaseFraction(f);
      progress.report(f, 0.0);
    };
    io.stopRequested = [] { return cancellationRequested(); };
    openfoam::ImportResult r = openfoam::importOpenFoam(job.scene, io);

    const CartesianGrid& g = r.grid;
    {
      const std::string tmp = options.outDir + "/result.h5.tmp";
      h5::File out(tmp, h5::File::Mode::Create);
      out.writeString("/scene", job.scene.source_json);
      out.write("/fields/alpha_p_mean", r.alphaPMean, {hsize_t(g.shape[2]), hsize_t(g.shape[1]), hsize_t(g.shape[0])});
      out.setAttribute("/fields/alpha_p_mean", "frames", r.summary.at("frames").get<std::int64_t>());
      out.flush();
    }
    fs::rename(options.outDir + "/result.h5.tmp", options.outDir + "/result.h5");
    xdmf::writeSidecar(options.outDir + "/result.h5", xdmfGrid(g));
    nlohmann::json summary = {{"kind", "import"}, {"status", "succeeded"}};
    summary.update(r.summary);
    if (job.scene.outputs.svg) {
      progress.setPhase("figures");
      analysis::PressureDropSeries dp;
      const nlohmann::json& p = r.summary["reference"]["pressure_drop"];
      if (p.is_object()) {
        h5::File db(io.databasePath, h5::File::Mode::ReadOnly);
        dp.pa = db.readDoubles(reference_series::pressureDrop);
        dp.dt = p.at("dt_s").get<double>();
        if (p.at("dominant_frequency_hz").is_number()) dp.dominantFrequency = p.at("dominant_frequency_hz").get<double>();
      }
      const auto db = FieldDatabase::open(io.databasePath, FrameStorage{kFigureCacheBytes});
      summary["figures"] =
          analysis::writeDatabaseFigures(job.scene, *db, dp, options.outDir, [] { return cancellationRequested(); });
    }
    summary["database"] = "database.h5";  // inside DIR, as the database job names it
    summary["wall_time_s"] = progress.wallTime();
    progress.report(1.0, 0.0, true);
    return summary;
  }
};

const bool registered = JobRunnerRegistry::add("import", "an OpenFOAM case imported as a field database",
                                               [] { return std::make_unique<ImportJob>(); });

}  // namespace
}  // namespace rcfd
