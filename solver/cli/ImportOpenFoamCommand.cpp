// rcfd-solve import-openfoam CASE_DIR --scene SCENE.json --out DB.h5 [--times A:B] [--cloud NAME]:
// an OpenFOAM case (reconstructed or decomposed, ASCII or binary, .gz or not) mapped onto the scene's
// grid as a field database, one frame per written time, with the spray-zone holdup and stays of its
// Lagrangian cloud under /reference/ (import/OpenFoamImport.hpp, docs/import.md). Prints what it read
// and mapped; --json adds the import summary as the last line.

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/Command.hpp"
#include "core/Errors.hpp"
#include "import/OpenFoamImport.hpp"
#include "jobs/Cancellation.hpp"
#include "scene/SceneLoader.hpp"
#include "tracers/TracerEffect.hpp"

namespace rcfd::cli {
namespace {

struct Options {
  std::string caseDir;
  std::string scene;
  std::string out;
  std::string times;
  std::string cloud;
  bool json = false;
};

int run(const Options& o) {
  const Scene scene = loadSceneFile(o.scene);
  openfoam::ImportOptions io;
  io.caseDir = o.caseDir;
  io.databasePath = o.out;
  io.cloud = o.cloud;
  io.velocitySpread = TracerEffectRegistry::needsVelocitySpread(scene.effects);
  if (!o.times.empty()) io.times = openfoam::TimeRange::parse(o.times, "--times");
  installCancellationHandlers();
  io.stopRequested = [] { return cancellationRequested(); };
  const openfoam::ImportResult r = openfoam::importOpenFoam(scene, io);
  const nlohmann::json& s = r.summary;
  std::cout << "imported " << s["case"].get<std::string>() << (s["decomposed"].get<bool>() ? " (decomposed, " : " (")
            << s["parts"] << " part(s), " << s["mesh_cells"] << " cells)\n  " << s["frames"] << " frames, t = "
            << s["first_time_s"] << " .. " << s["last_time_s"] << " s, dt_rec = " << s["dt_rec"] << " s\n  particles: "
            << s["particle_source"].get<std::string>()
            << (s.contains("cloud") ? " cloud " + s["cloud"].get<std::string>() : std::string()) << ", volume "
            << s["particle_volume"]["first_frame_m3"] << " m3 in the first frame, largest relative mapping error "
            << s["particle_volume"]["max_relative_error"] << "\n  reference: "
            << (s["reference"]["holdup"].is_null() ? "none" : "holdup")
            << (s["reference"]["residence_time"].is_null()
                    ? std::string()
                    : ", " + s["reference"]["residence_time"]["stays"].dump() + " spray-zone stays")
            << "\n  database: " << o.out << "\n";
  if (o.json) std::cout << s.dump() << "\n";
  return exit_code::success;
}

const bool registered = addCommand(
    "import-openfoam", "an OpenFOAM case (e.g. MPPICFoam) as a field database on the scene's grid", [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("CASE_DIR", o->caseDir, "OpenFOAM case directory (reconstructed, or with processor*/)")->required();
      app.add_option("--scene", o->scene, "scene file: grid, apparatus, spray zone (the case must use its coordinates)")
          ->required();
      app.add_option("--out", o->out, "field database to write (HDF5)")->required();
      app.add_option("--times", o->times, "written times to import, A:B, A: or :B [s] (default: all but 0)");
      app.add_option("--cloud", o->cloud, "Lagrangian cloud to import when the case has several");
      app.add_flag("--json", o->json, "print the import summary as JSON on the last line");
      return [o] { return run(*o); };
    });

}  // namespace
}  // namespace rcfd::cli
