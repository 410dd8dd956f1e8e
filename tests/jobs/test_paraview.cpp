// Every HDF5 file with fields that the jobs write opens in ParaView through its XDMF sidecar: a small
// database job, a spray job and a calibration job on its database, and an import job of a small
// OpenFOAM case, then scripts/check-paraview.py in
// ParaView's Python compares what ParaView shows (arrays, cell placement, values, time steps) with the
// files read by h5py. Skipped, saying why, where ParaView's Python is not installed
// (scripts/install-deps.sh installs it).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

#include "../import/FoamCaseWriter.hpp"
#include "../stability/StabilityCases.hpp"
#include "SmallScenes.hpp"
#include "core/Xdmf.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// $RCFD_PVPYTHON when set (a ParaView installed elsewhere, e.g. Kitware's binaries), else pvpython on the
/// PATH, else a python3 that imports paraview.simple and h5py; empty when there is none of them.
std::string paraviewPython() {
  if (const char* chosen = std::getenv("RCFD_PVPYTHON")) return ::access(chosen, X_OK) == 0 ? chosen : std::string();
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');) {
    if (!dir.empty() && ::access((fs::path(dir) / "pvpython").c_str(), X_OK) == 0) return (fs::path(dir) / "pvpython").string();
  }
  for (const char* python : {"/usr/bin/python3", "python3"}) {
    const std::string probe = std::string(python) + " -c 'import paraview.simple, h5py' >/dev/null 2>&1";
    if (std::system(probe.c_str()) == 0) return python;
  }
  return {};
}

struct CommandResult {
  int exitCode = -1;
  std::string output;
};

CommandResult runCommand(const std::string& command) {
  CommandResult r;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return r;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe)) r.output += buffer;
  const int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}


/// The installed ParaView's Python, or a skip naming what to install.
#define RCFD_REQUIRE_PARAVIEW(python)                                                                        \
  const std::string python = paraviewPython();                                                               \
  if (python.empty())                                                                                        \
    GTEST_SKIP() << "ParaView's Python is not installed (neither $RCFD_PVPYTHON, pvpython nor python3 with " \
                    "paraview.simple and h5py): install paraview, python3-paraview and python3-h5py "        \
                    "(scripts/install-deps.sh)";

}  // namespace

TEST(ParaView, OpensEveryJobOutputThroughItsSidecar) {
  RCFD_REQUIRE_PARAVIEW(python);
  const auto start = std::chrono::steady_clock::now();
  const fs::path dir = fs::path(testing::TempDir()) / ("paraview-" + std::to_string(::getpid()));
  fs::remove_all(dir);

  json scene = rcfd::test::demOnlyDatabaseScene();
  scene["outputs"]["svg"] = false;
  const rcfd::stability::Outcome database =
      rcfd::stability::runJob({{"kind", "database"}, {"scene", scene}, {"seed", 3}}, dir / "database", 120.0, 2);
  ASSERT_EQ(database.exitCode, 0) << database.describe();
  const fs::path databaseFile = dir / "database" / "out" / "database.h5";

  // The database's scene with tracers and every effect that writes cell fields.
  scene["rcfd"] = {{"dt", 0.005}, {"tracers", 400}, {"d0", 5e-4}};
  scene["effects"] = rcfd::stability::allTracerEffects();
  const rcfd::stability::Outcome spray =
      rcfd::stability::runJob(rcfd::stability::sprayJob(scene, databaseFile, 0.2, 7), dir / "spray", 120.0, 2);
  ASSERT_EQ(spray.exitCode, 0) << spray.describe();

  const json calibrationJob = {{"kind", "calibration"}, {"scene", scene}, {"database", databaseFile.string()},
                               {"duration", 0.2}, {"discard", 0.05}, {"d0_values", {0.0, 1e-3}}, {"seed", 5}};
  const rcfd::stability::Outcome calibration = rcfd::stability::runJob(calibrationJob, dir / "calibration", 120.0, 2);
  ASSERT_EQ(calibration.exitCode, 0) << calibration.describe();
  const double jobSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  const std::vector<fs::path> sidecars = {
      dir / "database" / "out" / "database.xmf",         dir / "database" / "out" / "result.xmf",
      dir / "spray" / "out" / "result.xmf",              dir / "calibration" / "out" / "result.xmf",
      dir / "calibration" / "out" / "runs" / "d0_0" / "result.xmf"};
  std::string command = python + " " + std::string(RCFD_SOURCE_DIR) + "/scripts/check-paraview.py --grid " +
                        databaseFile.string();
  for (const auto& s : sidecars) {
    ASSERT_TRUE(fs::exists(s)) << s;
    command += " " + s.string();
  }
  // The calibration's mid-plane maps: the recurrence's and one per D0 run (the sweep may have grown).
  command += " --layer-map /calibration/recurrence/alpha_p_midplane";
  const json calibrationSummary = json::parse(std::ifstream(dir / "calibration" / "out" / "summary.json"));
  const std::size_t runs = calibrationSummary.at("d0").size();
  ASSERT_GE(runs, 2u);
  for (std::size_t i = 0; i < runs; ++i)
    command += " --layer-map /calibration/runs/d0_" + std::to_string(i) + "/field_average/alpha_p_midplane";
  // The fields each kind of file must show; the script finds the others by their shape.
  for (const char* name : {"alpha_p", "u_p", "u_g", "grid/fluid_fraction", "fields/alpha_p_mean",
                           "deposition_maps/rate_density", "field_average/alpha_p_tracers",
                           "field_average/alpha_p_recurrence", "calibration/recurrence/alpha_p_midplane",
                           "calibration/runs/d0_1/field_average/alpha_p_midplane"}) {
    command += std::string(" --expect ") + name;
  }
  const auto checkStart = std::chrono::steady_clock::now();
  const CommandResult check = runCommand(command);
  const double checkSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - checkStart).count();
  if (check.exitCode == 77) GTEST_SKIP() << check.output;
  EXPECT_EQ(check.exitCode, 0) << command << "\n" << check.output;
  std::printf("jobs %.1f s, ParaView check %.1f s (%s)\n", jobSeconds, checkSeconds, python.c_str());
  if (!HasFailure()) fs::remove_all(dir);
}

// The import job's database (frames over time) and result.h5 on a case of 2 x 2 mesh cells per grid cell.
TEST(ParaView, OpensTheImportsOutputsThroughTheirSidecars) {
  RCFD_REQUIRE_PARAVIEW(python);
  const fs::path dir = fs::path(testing::TempDir()) / ("paraview-import-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const json scene = rcfd::test::importTestScene();
  rcfd::test::LatticeMesh mesh;
  for (int i = 0; i <= 8; ++i) mesh.xs.push_back(-0.02 + 0.005 * i);
  for (int j = 0; j <= 8; ++j) mesh.ys.push_back(0.005 * j);
  mesh.zs = {0.0, 0.01};
  const fs::path root = dir / "case";
  mesh.write(root / "constant/polyMesh", {rcfd::test::Encoding::Ascii, false});
  for (int n = 1; n <= 4; ++n) {
    const fs::path t = root / std::to_string(n);
    std::vector<Eigen::Vector3d> gas;
    std::vector<double> pressure;
    for (const auto& c : mesh.cells()) {
      gas.push_back({0.1 * n, 1.0 + mesh.centre(c).x(), 0.0});
      pressure.push_back(100.0 - 1000.0 * mesh.centre(c).y());
    }
    rcfd::test::writeVolVectorField(t / "U.air", gas, {rcfd::test::Encoding::Ascii, false});
    rcfd::test::writeVolScalarField(t / "p", pressure, {rcfd::test::Encoding::Ascii, false}, "[0 2 -2 0 0 0 0]");
    std::vector<rcfd::test::TestParcel> parcels;
    for (int k = 0; k < 6; ++k) {
      rcfd::test::TestParcel p;
      p.x = {-0.015 + 0.006 * k, 0.004 + 0.005 * ((k + n) % 6), 0.005};
      p.u = {0.0, 0.5 * k, 0.0};
      p.nParticle = 20;
      p.origId = k;
      parcels.push_back(p);
    }
    rcfd::test::writeCloud(t / "lagrangian/cloud", parcels, {rcfd::test::Encoding::Ascii, false});
  }
  const rcfd::stability::Outcome import = rcfd::stability::runJob(
      {{"kind", "import"}, {"scene", scene}, {"case_dir", root.string()}}, dir / "import", 60.0, 1);
  ASSERT_EQ(import.exitCode, 0) << import.describe();
  const fs::path out = dir / "import" / "out";
  std::string command = python + " " + std::string(RCFD_SOURCE_DIR) + "/scripts/check-paraview.py --grid " +
                        (out / "database.h5").string() + " " + (out / "database.xmf").string() + " " +
                        (out / "result.xmf").string();
  for (const char* name : {"alpha_p", "u_p", "u_g", "grid/fluid_fraction", "fields/alpha_p_mean"})
    command += std::string(" --expect ") + name;
  const CommandResult check = runCommand(command);
  if (check.exitCode == 77) GTEST_SKIP() << check.output;
  EXPECT_EQ(check.exitCode, 0) << command << "\n" << check.output;
  if (!HasFailure()) fs::remove_all(dir);
}
