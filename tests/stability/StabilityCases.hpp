#pragma once
/// \file StabilityCases.hpp
/// The scenes, databases and job files the hard cases of the stability suite start from: a small box
/// with an open top sprayed from below, and an analytic database of a swaying spout in it, which each
/// case then pushes to one extreme.

#include <hdf5.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "StabilityHarness.hpp"
#include "fields/AnalyticDatabase.hpp"

namespace rcfd::stability {

/// A fresh directory for one case under the test program's temporary directory.
inline fs::path caseDirectory(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rcfd-stability-" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

/// Every tracer and spray effect that runs on a database without the velocity spread.
inline json allTracerEffects() {
  return json::array({"transport", "walls", "fluctuation", "free_flight", "tracer_volume_fraction", "probes",
                      "residence_time", "field_average", "spray", "deposition", "coverage", "deposition_maps"});
}

/// A 10 x 15 x 4 cm box with an open top, 1 cm cells, 2000 tracers, a nozzle at the bottom spraying up
/// through a spray zone, two probes, every tracer and spray effect.
inline json boxScene() {
  json s = json::parse(R"({
    "name": "stability-box",
    "apparatus": {"type": "box", "size": [0.1, 0.15, 0.04], "outlet_top": true},
    "grid": {"cell_size": 0.01},
    "gas": {}, "particles": {},
    "process": {"bed_mass": 0.3},
    "rcfd": {"dt": 0.005, "tracers": 2000, "d0": 5e-4},
    "spray": {"nozzle_position": [0.0, 0.005, 0.02], "nozzle_diameter": 0.002, "parcels_per_s": 4000,
              "spray_zone": {"apex": [0.0, 0.005, 0.02], "y_min": 0.01, "y_max": 0.08}},
    "probes": [{"name": "centre", "position": [0.0, 0.05, 0.02]}, {"name": "side", "position": [0.04, 0.02, 0.01]}],
    "outputs": {"svg": false}
  })");
  s["effects"] = allTracerEffects();
  return s;
}

/// The prism of the ProCell shrunk to 6 x 20 x 1 cm, with draft plates, 5 mm cells.
inline json prismScene() {
  json s = boxScene();
  s["name"] = "stability-prism";
  s["apparatus"] = json::parse(R"({"type": "prismatic_spouted_bed", "width": 0.06, "depth": 0.01, "height": 0.2,
      "prism_angle_deg": 60, "inlet_width": 0.01,
      "draft_plates": {"height": 0.04, "gap": 0.016, "elevation": 0.03, "thickness": 0.002}})");
  s["grid"] = {{"cell_size", 0.005}};
  s["process"]["bed_mass"] = 0.01;
  s["spray"] = json::parse(R"({"nozzle_position": [0.0, 0.002, 0.005], "nozzle_diameter": 0.002,
      "parcels_per_s": 4000, "spray_zone": {"apex": [0.0, 0.002, 0.005], "y_min": 0.01, "y_max": 0.06}})");
  s["probes"] = json::parse(R"([{"name": "tube", "position": [0.0, 0.05, 0.005]}])");
  return s;
}

/// Values of one frame of the swaying spout at time t: alpha_P, u_P and u_G at a cell centre p.
struct SpoutValues {
  double alpha, upy, ugx, ugy;
};
inline SpoutValues swayingSpout(const Eigen::Vector3d& p, int n, double t, double height) {
  const double phase = 2.0 * std::numbers::pi * t / 0.1;  // a period of 20 frames at 5 ms
  const bool spout = std::abs(p.x() - 0.01 * std::sin(phase)) < 0.02;
  return {p.y() < 0.45 * height ? (spout ? 0.15 : 0.5) : 0.0, spout ? 1.0 : -0.2, 0.5 * std::sin(phase + 40 * p.y()) + 0.01 * n,
          spout ? 6.0 : 1.0};
}

/// The swaying spout as a frame function for `grid`.
inline FrameFunction spoutFrames(const CartesianGrid& grid) {
  const double height = grid.origin.y() + grid.spacing.y() * grid.shape[1];
  return [grid, height](int n, double t, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      const SpoutValues v = swayingSpout(grid.cellCenter(ijk[0], ijk[1], ijk[2]), n, t, height);
      f.alpha_p[std::size_t(c)] = float(v.alpha);
      f.u_p[3 * c + 1] = float(v.upy);
      f.u_g[3 * c] = float(v.ugx);
      f.u_g[3 * c + 1] = float(v.ugy);
    }
  };
}

/// Writes a database for `scene`'s grid to `file`: `frames` frames every `dtRec` from `fill`
/// (default: the swaying spout).
inline void writeDatabase(const json& scene, const fs::path& file, int frames = 40, double dtRec = 0.005,
                          FrameFunction fill = {}, FieldDatabaseWriterOptions options = {}) {
  const SceneGrid g = sceneGrid(scene);
  if (!fill) fill = spoutFrames(g.grid);
  writeAnalyticDatabase(file.string(), g.grid, g.fluid, dtRec, frames, fill, scene.dump(), options);
}

/// A spray job on `database` for `duration` simulated seconds.
inline json sprayJob(const json& scene, const fs::path& database, double duration, std::uint64_t seed = 1) {
  return {{"kind", "spray"}, {"scene", scene}, {"database", database.string()}, {"duration", duration}, {"seed", seed}};
}

/// Overwrites one float of a frame dataset in place (the raw HDF5 API: the writer refuses bad values, a
/// program other than rcfd need not).
inline void pokeFloat(const fs::path& file, const std::string& dataset, hsize_t flatIndex, float value) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t d = H5Dopen2(f, dataset.c_str(), H5P_DEFAULT);
  const hid_t space = H5Dget_space(d);
  const int rank = H5Sget_simple_extent_ndims(space);
  const std::size_t axes = std::size_t(rank);
  std::vector<hsize_t> dims(axes), start(axes), one(axes, 1);
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  for (int r = rank - 1; r >= 0; --r) {
    start[std::size_t(r)] = flatIndex % dims[std::size_t(r)];
    flatIndex /= dims[std::size_t(r)];
  }
  H5Sselect_hyperslab(space, H5S_SELECT_SET, start.data(), nullptr, one.data(), nullptr);
  const hid_t memory = H5Screate_simple(1, one.data(), nullptr);
  H5Dwrite(d, H5T_NATIVE_FLOAT, memory, space, H5P_DEFAULT, &value);
  H5Sclose(memory);
  H5Sclose(space);
  H5Dclose(d);
  H5Fclose(f);
}

}  // namespace rcfd::stability
