// rcfd-solve database-figures DB.h5 --out DIR [--checkpoint FILE]: the database job's figures
// (analysis/DatabaseFigures.hpp) for any field database that carries its scene: alpha_P on the
// mid-plane at four instants and averaged over all frames, and the pressure-drop series when the file
// (/reference/pressure_drop/pa) or a database job's checkpoint holds one. Prints the time-averaged
// alpha_P at the scene's probes as JSON, and with --profiles Y1,Y2,.. its profiles across x at those
// heights (analysis/AlphaProfiles.hpp). Useful for a database of an interrupted job or of another
// program.

#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "analysis/AlphaProfiles.hpp"
#include "analysis/DatabaseFigures.hpp"
#include "analysis/SeriesSpectrum.hpp"
#include "cfddem/ReferenceRecorder.hpp"
#include "cli/Command.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "fields/FieldDatabase.hpp"
#include "scene/SceneLoader.hpp"

namespace rcfd::cli {
namespace {

/// Frames held at once while drawing: enough for the largest grids, far below any database.
constexpr std::int64_t kCacheBytes = 256LL << 20;
constexpr std::size_t kSpectrumSamples = 4;

struct Options {
  std::string database;
  std::string out = ".";
  std::string checkpoint;
  std::vector<double> profileHeights;  ///< [m]
};

/// The pressure-drop series of the database or, failing that, of a database job's checkpoint (its
/// /reference group, sampled at the scene's probe_rate).
analysis::PressureDropSeries pressureDrop(const Options& o, const Scene& scene) {
  analysis::PressureDropSeries p;
  h5::File f(o.database, h5::File::Mode::ReadOnly);
  if (f.exists(reference_series::pressureDrop)) {
    p.pa = f.readDoubles(reference_series::pressureDrop);
    p.dt = f.doubleAttribute(reference_series::pressureDrop, "dt");
  } else if (!o.checkpoint.empty()) {
    p.pa = h5::File(o.checkpoint, h5::File::Mode::ReadOnly).readDoubles("/reference/pressure_drop");
    p.dt = 1.0 / scene.dem.probe_rate;
  }
  return p;
}

int run(const Options& o) {
  auto db = FieldDatabase::open(o.database, FrameStorage{kCacheBytes});
  const Scene scene = loadSceneText(db->sceneJson(), o.database + ":/scene");
  std::filesystem::create_directories(o.out);
  analysis::PressureDropSeries dp = pressureDrop(o, scene);
  nlohmann::json out = {{"frames", db->frameCount()}, {"dt_rec", db->dtRec()}};
  if (dp.pa.size() >= kSpectrumSamples) {
    const auto s = analysis::seriesSpectrum(dp.pa, dp.dt);
    dp.dominantFrequency = s.dominantFrequency;
    out["pressure_drop"] = {{"samples", dp.pa.size()}, {"mean_pa", s.mean}, {"std_pa", s.std},
                            {"dominant_frequency_hz", s.dominantFrequency ? nlohmann::json(*s.dominantFrequency)
                                                                          : nlohmann::json()},
                            {"frequency_resolution_hz", s.resolution}};
  }
  out["figures"] = analysis::writeDatabaseFigures(scene, *db, dp, o.out);
  const std::vector<double> mean = analysis::meanAlphaP(*db);
  nlohmann::json probes = nlohmann::json::array();
  for (const auto& p : scene.probes) {
    probes.push_back({{"name", p.name}, {"alpha_p_mean", mean[std::size_t(db->grid().flatIndexOf(p.position))]}});
  }
  out["probes"] = probes;
  if (!o.profileHeights.empty()) {
    nlohmann::json profiles = nlohmann::json::array();
    const auto rows = analysis::alphaProfiles(scene, *db, mean, o.profileHeights);
    out["figures"].push_back(analysis::writeAlphaProfileFigure(rows, o.out));
    for (const auto& p : rows) {
      nlohmann::json cells = nlohmann::json::array();
      for (const auto& c : p.cells)
        cells.push_back({{"x", c.x}, {"alpha_p_mid", c.alphaMid}, {"alpha_p_depth", c.alphaDepth}, {"open_mid", c.openMid}});
      profiles.push_back({{"y", p.y}, {"cells", cells}});
    }
    out["profiles"] = profiles;
  }
  std::cout << out.dump(2) << "\n";
  return exit_code::success;
}

const bool registered = addCommand(
    "database-figures", "alpha_P mid-plane snapshots, time average and pressure drop of a field database",
    [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("DB", o->database, "field database (HDF5) with its scene in /scene")->required();
      app.add_option("--out", o->out, "directory for the SVG files (default .)");
      app.add_option("--checkpoint", o->checkpoint,
                     "a database job's checkpoint.h5: the pressure drop recorded so far, when the database has none");
      app.add_option("--profiles", o->profileHeights,
                     "heights [m] (comma-separated) at which to print the time-averaged alpha_P across x")
          ->delimiter(',');
      return [o] { return run(*o); };
    });

}  // namespace
}  // namespace rcfd::cli
