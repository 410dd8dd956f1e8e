// rcfd-solve droplet-paths DB.h5 [--launches N] [--paths N] [--max-seconds S] [--heights Y1,Y2,..]
// [--seed N]: where the bed of a field database catches the spray (spray/DropletPaths.hpp): droplet
// paths from the nozzle through the frames in their own order, with the scene's deposition model on the
// frames' alpha_P. Prints JSON: the shares that leave through the outlet, reach a wall, stay airborne
// and deposit; the overspray's spread over the launch instants; per height, the share deposited below
// it and the optical depth on first reaching it.

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "spray/DropletPaths.hpp"
#include "cli/Command.hpp"
#include "core/Errors.hpp"
#include "fields/FieldDatabase.hpp"
#include "scene/SceneLoader.hpp"

namespace rcfd::cli {
namespace {

/// Frames held at once: a path reads max-seconds / dt_rec consecutive frames, two threads two such runs.
constexpr std::int64_t kCacheBytes = 1LL << 30;

struct Options {
  std::string database;
  DropletPathOptions paths;
};

int run(const Options& o) {
  auto db = FieldDatabase::open(o.database, FrameStorage{kCacheBytes});
  const Scene scene = loadSceneText(db->sceneJson(), o.database + ":/scene");
  const auto r = dropletPaths(scene, *db, o.paths);
  nlohmann::json heights = nlohmann::json::array();
  for (const auto& h : r.heights) {
    heights.push_back({{"y_m", h.y},
                       {"reached", h.reached},
                       {"deposited_below", h.depositedBelow},
                       {"optical_depth", {{"p10", h.opticalDepthP10}, {"median", h.opticalDepthMedian}, {"p90", h.opticalDepthP90}}}});
  }
  const nlohmann::json out = {
      {"database", o.database},
      {"frames", db->frameCount()},
      {"dt_rec", db->dtRec()},
      {"launches", r.launches},
      {"paths_per_launch", r.pathsPerLaunch},
      {"max_seconds", r.maxSeconds},
      {"seed", o.paths.seed},
      {"outlet", r.outlet},
      {"wall", r.wall},
      {"airborne", r.airborne},
      {"deposited", r.deposited},
      {"overspray", r.outlet + r.wall},
      {"launch_overspray", {{"median", r.launchOversprayMedian}, {"p90", r.launchOversprayP90}, {"max", r.launchOversprayMax},
                            {"threshold", 1e-3}, {"share_above_threshold", r.launchesAbove1e3}}},
      {"heights", heights}};
  std::cout << out.dump(2) << "\n";
  return exit_code::success;
}

const bool registered = addCommand(
    "droplet-paths", "where a field database's bed catches the spray: droplet paths through its frames (Eq. 11-14)",
    [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("DB", o->database, "field database (HDF5) with its scene in /scene")->required();
      app.add_option("--launches", o->paths.launches, "launch instants spread over the frames (default 64)")
          ->check(CLI::Range(1, 100000));
      app.add_option("--paths", o->paths.pathsPerLaunch, "paths from each instant (default 64)")
          ->check(CLI::Range(1, 100000));
      app.add_option("--max-seconds", o->paths.maxSeconds,
                     "a path still airborne after this counts as airborne [s] (default 1)")
          ->check(CLI::PositiveNumber);
      app.add_option("--heights", o->paths.heights, "heights [m] (comma-separated) to report the deposit below")
          ->delimiter(',');
      app.add_option("--seed", o->paths.seed, "seed of the launch points (default 1)");
      return [o] { return run(*o); };
    });

}  // namespace
}  // namespace rcfd::cli
