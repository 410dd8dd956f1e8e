#pragma once
// A small field database for server tests and the server benchmark: the scene's grid with a spout
// swaying left and right (period 0.25 s) and an annulus sliding down, so tracers cross the spray zone
// and frames differ for the recurrence path. Written with rcfd::writeAnalyticDatabase (the real
// writer, the docs/formats.md layout), so a spray job on it runs the real solver. Header-only so both
// tests/server and bench/server_load.cpp can include it.

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "fields/AnalyticDatabase.hpp"
#include "geometry/Apparatus.hpp"
#include "scene/SceneLoader.hpp"

namespace rcfd::test {

inline constexpr int kSmallDatabaseFrames = 24;

/// The scene with `tracers` tracers, so a spray job on the small database takes seconds.
inline nlohmann::json withTracers(nlohmann::json scene, long tracers) {
  scene["rcfd"]["tracers"] = tracers;
  return scene;
}

inline void writeSmallDatabase(const nlohmann::json& sceneJson, const std::filesystem::path& path) {
  const rcfd::Scene scene = rcfd::loadScene(sceneJson, "test scene");
  const rcfd::Apparatus apparatus(scene.apparatus);
  const auto grid = rcfd::makeGrid(apparatus, scene.grid);
  const auto open = rcfd::openFractions(apparatus, grid);
  const std::vector<float> fluid(open.begin(), open.end());
  rcfd::writeAnalyticDatabase(
      path.string(), grid, fluid, scene.rcfd.dt, kSmallDatabaseFrames,
      [&](int, double t, rcfd::FieldFrame& f) {
        const double centre = 0.01 * std::sin(2.0 * M_PI * t / 0.25);
        for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
          const auto ijk = grid.cellIjk(c);
          const auto p = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
          const double dx = p.x() - centre;
          const bool spout = std::abs(dx) < 0.015 && p.y() < 0.25;
          const bool bed = p.y() < 0.12;
          const auto i = std::size_t(c);
          f.alpha_p[i] = float(spout ? 0.1 : (bed ? 0.5 : 0.01));
          f.u_p[3 * i] = float(spout ? 0.2 * dx / 0.015 : (bed ? -0.1 * std::copysign(1.0, dx) : 0.0));
          f.u_p[3 * i + 1] = float(spout ? 2.0 : (bed ? -0.15 : -1.0));
          f.u_g[3 * i + 1] = float(spout ? 10.0 : 1.5);
        }
      },
      sceneJson.dump());
}

}  // namespace rcfd::test
