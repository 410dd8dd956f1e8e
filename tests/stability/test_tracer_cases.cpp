// Hard cases of the tracer stage, each a whole spray job through rcfd-solve on an analytic database
// pushed to one extreme (docs/stability.md, "Tracers"). Every case ends with exit 0 and outputs that are
// finite and bounded (tracers all there and inside the apparatus, coverage in [0, 1], the spray's books
// closed), or with exit 2 naming the field, within its time bound.
#include <gtest/gtest.h>

#include <random>

#include "StabilityCases.hpp"
#include "core/Hdf5.hpp"

using namespace rcfd::stability;

namespace {

/// Seconds any of these small jobs may take before it counts as a hang (they take about one).
constexpr double kBound = 120.0;

void expectClean(const Outcome& o, const json& job, const fs::path& dir) {
  EXPECT_FALSE(o.timedOut) << o.describe();
  EXPECT_EQ(o.exitCode, 0) << o.describe();
  EXPECT_EQ(outcomeProblem(o, job, dir), "");
}

json summaryOf(const fs::path& dir) { return json::parse(std::ifstream(dir / "out" / "summary.json")); }

std::vector<double> dataset(const fs::path& dir, const std::string& name) {
  rcfd::h5::File f((dir / "out" / "result.h5").string(), rcfd::h5::File::Mode::ReadOnly);
  return f.readDoubles(name);
}

}  // namespace

// D0 = 0: the relaxation does nothing; tracers follow u_P^rec alone and gather where it converges (the
// paper's finding), but stay inside, all of them, with every output finite. For each relaxation model.
TEST(TracerCases, D0ZeroRelaxesNothingAndKeepsEveryTracerInside) {
  for (const char* model : {"fluctuation", "directed_relaxation"}) {
    SCOPED_TRACE(model);
    const fs::path dir = caseDirectory(std::string("d0-zero-") + model);
    json scene = boxScene();
    scene["rcfd"]["d0"] = 0.0;
    scene["effects"] = allTracerEffects();
    scene["effects"][2] = model;
    writeDatabase(scene, dir / "db.h5");
    const json job = sprayJob(scene, dir / "db.h5", 0.5);
    expectClean(runJob(job, dir, kBound), job, dir);
  }
}

// D0 = 0.1 m2/s, 200 x the paper's: Eq. (10)'s speed reaches u_fluc_max (1 m/s) in every over-packed
// cell and the directed relaxation its half-cell-per-step bound (D0 dt / h^2 = 5); nothing grows
// without bound.
TEST(TracerCases, D0OfPointOneIsBoundedByTheSpeedCaps) {
  for (const char* model : {"fluctuation", "directed_relaxation"}) {
    SCOPED_TRACE(model);
    const fs::path dir = caseDirectory(std::string("d0-large-") + model);
    json scene = boxScene();
    scene["rcfd"]["d0"] = 0.1;
    scene["effects"][2] = model;
    writeDatabase(scene, dir / "db.h5");
    const json job = sprayJob(scene, dir / "db.h5", 0.5);
    expectClean(runJob(job, dir, kBound), job, dir);
  }
}

// dt = 10 dt_rec: the tracers would skip nine of every ten frames; refused naming /rcfd/dt and the rule
// (dt_rec / k, k a whole number >= 1).
TEST(TracerCases, ATimeStepTenTimesTheDatabaseIntervalIsRefusedNamingRcfdDt) {
  const fs::path dir = caseDirectory("dt-ten-times");
  json scene = boxScene();
  scene["rcfd"]["dt"] = 0.05;
  writeDatabase(scene, dir / "db.h5", 40, 0.005);
  const Outcome o = runJob(sprayJob(scene, dir / "db.h5", 0.5), dir, kBound);
  EXPECT_EQ(inputErrorProblem(o), "");
  EXPECT_NE(o.stderrText.find("/rcfd/dt"), std::string::npos) << o.stderrText;
  EXPECT_NE(o.stderrText.find("dt_rec / k for a whole number k >= 1"), std::string::npos) << o.stderrText;
}

// u_P^rec of 100 m/s in every cell, in directions that change from cell to cell and frame to frame:
// 50 cells a step, sub-stepped up to 64 times and held by the exact wall test beyond that.
TEST(TracerCases, RecurrenceVelocitiesOf100MetresPerSecondKeepEveryTracerInside) {
  const fs::path dir = caseDirectory("fast-field");
  const json scene = boxScene();
  const SceneGrid g = sceneGrid(scene);
  writeDatabase(scene, dir / "db.h5", 40, 0.005, [grid = g.grid](int n, double, rcfd::FieldFrame& f) {
    std::mt19937_64 rng(std::uint64_t(n) + 7);
    std::normal_distribution<double> normal;
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      Eigen::Vector3d u(normal(rng), normal(rng), normal(rng));
      u *= 100.0 / u.norm();
      f.alpha_p[std::size_t(c)] = 0.3f;
      for (int d = 0; d < 3; ++d) f.u_p[3 * c + d] = float(u[d]), f.u_g[3 * c + d] = float(-u[d]);
    }
  });
  const json job = sprayJob(scene, dir / "db.h5", 0.5);
  const Outcome o = runJob(job, dir, kBound);
  expectClean(o, job, dir);
}

// alpha_P^rec = 0 in every cell of every frame: no particles anywhere, so the tracers are placed by open
// volume and fly freely (drag and gravity); the deposition finds tracers only where they fell.
TEST(TracerCases, AlphaRecZeroEverywhereIsAllFreeFlight) {
  const fs::path dir = caseDirectory("alpha-zero");
  const json scene = boxScene();
  const SceneGrid g = sceneGrid(scene);
  writeDatabase(scene, dir / "db.h5", 40, 0.005, [grid = g.grid](int, double, rcfd::FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) f.u_g[3 * c + 1] = 2.0f;
  });
  const json job = sprayJob(scene, dir / "db.h5", 1.0);
  expectClean(runJob(job, dir, kBound), job, dir);
  // Free flight under gravity with a 2 m/s updraft: 1.8 mm beads fall (terminal velocity ~ 9 m/s in
  // still air); the tracers end in the lower half.
  const auto y = dataset(dir, "/tracers/y");
  double mean = 0.0;
  for (const double v : y) mean += v / double(y.size());
  EXPECT_LT(mean, 0.075);
}

// alpha_P^rec = 0.74 (random close packing and beyond what a bed reaches) in every cell: Eq. (10) and
// the deposition (evaluated with alpha_P capped at 0.74, docs/physics.md) stay finite.
TEST(TracerCases, AlphaRecOfPointSevenFourEverywhereStaysBounded) {
  const fs::path dir = caseDirectory("alpha-dense");
  json scene = boxScene();
  scene["process"]["bed_mass"] = 0.74 * 0.1 * 0.15 * 0.04 * 1040.0;
  const SceneGrid g = sceneGrid(scene);
  writeDatabase(scene, dir / "db.h5", 40, 0.005, [grid = g.grid](int n, double, rcfd::FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      f.alpha_p[std::size_t(c)] = 0.74f;
      f.u_p[3 * c + 1] = float(0.1 * std::sin(0.3 * double(c + n)));
      f.u_g[3 * c + 1] = 3.0f;
    }
  });
  const json job = sprayJob(scene, dir / "db.h5", 0.5);
  expectClean(runJob(job, dir, kBound), job, dir);
  EXPECT_GT(summaryOf(dir)["mass_balance"]["deposited_kg"].get<double>(), 0.0);
}

// Tracers put exactly on walls, edges, corners and the draft plates' tips (through a checkpoint, as a
// resumed run would load them) move on and stay inside.
TEST(TracerCases, TracersStartedOnWallsCornersAndPlateTipsStayInside) {
  for (const bool prism : {false, true}) {
    SCOPED_TRACE(prism ? "prism with draft plates" : "box");
    const fs::path dir = caseDirectory(prism ? "on-walls-prism" : "on-walls-box");
    json scene = prism ? prismScene() : boxScene();
    scene["rcfd"]["tracers"] = 400;
    writeDatabase(scene, dir / "db.h5");
    const json job = sprayJob(scene, dir / "db.h5", 0.3);
    const Outcome first = runJob(job, dir, kBound, 1, {"--stop-after-steps", "1"});
    ASSERT_EQ(first.exitCode, 130) << first.describe();
    // The special points of the outline.
    std::vector<Eigen::Vector3d> points;
    if (!prism) {
      const double hx = 0.05, h = 0.15, d = 0.04;
      for (const double x : {-hx, 0.0, hx})
        for (const double y : {0.0, 0.075, h})
          for (const double z : {0.0, 0.02, d}) points.emplace_back(x, y, z);
    } else {
      const double w = 0.03, h = 0.2, d = 0.01, slot = 0.005, vTop = (w - slot) * std::tan(std::numbers::pi / 3);
      const double inner = 0.008, outer = 0.01, low = 0.03, high = 0.07;
      for (const double z : {0.0, 0.005, d}) {
        for (const double s : {-1.0, 1.0}) {
          for (const auto& xy : std::vector<std::pair<double, double>>{
                   {slot, 0.0}, {w, vTop}, {w, h}, {w, 0.1}, {0.5 * (slot + w), 0.5 * vTop},  // V, walls, top
                   {inner, low}, {outer, low}, {inner, high}, {outer, high},                 // plate corners (tips)
                   {inner, 0.05}, {outer, 0.05}, {0.009, low}, {0.009, high}})               // faces, edge middles
            points.emplace_back(s * xy.first, xy.second, z);
        }
        points.emplace_back(0.0, 0.0, z);  // the inlet slot
        points.emplace_back(0.0, h, z);    // the outlet
      }
    }
    std::vector<double> x(400), y(400), z(400);
    for (std::size_t i = 0; i < 400; ++i) {
      const auto& p = points[i % points.size()];
      x[i] = p.x(), y[i] = p.y(), z[i] = p.z();
    }
    {
      rcfd::h5::File c((dir / "out" / "checkpoint.h5").string(), rcfd::h5::File::Mode::ReadWrite);
      c.write("/cloud/x", x), c.write("/cloud/y", y), c.write("/cloud/z", z);
      c.write("/cloud/vx", std::vector<double>(400, 0.0)), c.write("/cloud/vy", std::vector<double>(400, 0.0));
      c.write("/cloud/vz", std::vector<double>(400, 0.0));
    }
    expectClean(runJob(job, dir, kBound), job, dir);
  }
}

// One state repeated in every frame: every pair of frames is equally similar (R = 1 everywhere), and
// each path type still strings the frames together; the run is the steady field's.
TEST(TracerCases, ADatabaseOfOneRepeatedStateRunsOnEveryPathType) {
  for (const char* path : {"paper", "markov"}) {
    SCOPED_TRACE(path);
    const fs::path dir = caseDirectory(std::string("one-state-") + path);
    json scene = boxScene();
    scene["rcfd"]["path"] = {{"type", path}, {"correlation_window", 5}};
    const SceneGrid g = sceneGrid(scene);
    const auto spout = spoutFrames(g.grid);
    writeDatabase(scene, dir / "db.h5", 40, 0.005, [spout](int, double, rcfd::FieldFrame& f) { spout(0, 0.0, f); });
    const json job = sprayJob(scene, dir / "db.h5", 0.5);
    expectClean(runJob(job, dir, kBound), job, dir);
  }
}

// Frames that jump: each frame independent random noise, so no two frames are similar (recurrence
// with nothing to recur to). The paths still jump to the least dissimilar frame; the run stays bounded.
TEST(TracerCases, FramesWithoutAnySimilarFrameStillGiveAPathAndABoundedRun) {
  for (const char* path : {"paper", "markov"}) {
    SCOPED_TRACE(path);
    const fs::path dir = caseDirectory(std::string("jumping-") + path);
    json scene = boxScene();
    scene["rcfd"]["path"] = {{"type", path}, {"correlation_window", 5}};
    const SceneGrid g = sceneGrid(scene);
    writeDatabase(scene, dir / "db.h5", 40, 0.005, [grid = g.grid](int n, double, rcfd::FieldFrame& f) {
      std::mt19937_64 rng(std::uint64_t(n) * 7919 + 1);
      std::uniform_real_distribution<double> u(0.0, 1.0);
      for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
        f.alpha_p[std::size_t(c)] = float(0.6 * u(rng));
        for (int d = 0; d < 3; ++d) f.u_p[3 * c + d] = float(4.0 * u(rng) - 2.0), f.u_g[3 * c + d] = float(20.0 * u(rng) - 10.0);
      }
    });
    const json job = sprayJob(scene, dir / "db.h5", 0.5);
    expectClean(runJob(job, dir, kBound), job, dir);
  }
}
