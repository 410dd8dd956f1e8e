// The OpenFOAM import (solver/import/, docs/import.md) on small hand-written cases: a hex lattice mesh
// with unequal cell widths over a 4 x 4 x 1 scene grid, gas velocity and a Lagrangian cloud of parcels
// with identities moving through the spray zone on known paths; the same case reconstructed (ASCII,
// partly .gz) and decomposed into two processors (binary, partly .gz); an Eulerian particle phase;
// and malformed files.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>

#include "FoamCaseWriter.hpp"
#include "analysis/ReferenceStatistics.hpp"
#include "cfddem/ReferenceRecorder.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "fields/FieldDatabase.hpp"
#include "import/FoamFile.hpp"
#include "import/OpenFoamImport.hpp"
#include "import/OpenFoamMesh.hpp"
#include "jobs/JobRunner.hpp"
#include "scene/SceneLoader.hpp"

namespace fs = std::filesystem;
using nlohmann::json;
using rcfd::test::Encoding;
using rcfd::test::FileStyle;
using rcfd::test::LatticeMesh;
using rcfd::test::TestParcel;

namespace {

json sceneDocument() { return rcfd::test::importTestScene(); }

// Mesh planes: two mesh cells of unequal width per grid cell along x and y, two along z.
LatticeMesh latticeMesh() {
  LatticeMesh m;
  m.xs = {-0.02, -0.017, -0.01, -0.004, 0.0, 0.005, 0.01, 0.012, 0.02};
  m.ys = {0.0, 0.003, 0.01, 0.016, 0.02, 0.025, 0.03, 0.031, 0.04};
  m.zs = {0.0, 0.004, 0.01};
  return m;
}

const std::vector<std::string> kTimes = {"0.1", "0.2", "0.3", "0.4", "0.5"};

Eigen::Vector3d gasVelocity(const Eigen::Vector3d& c) {
  // x linear (its volume mean over a grid cell is its value at the cell's centroid), y nonlinear.
  return {100.0 * c.x() + 1.0, 1e4 * (c.x() + 0.02) * (c.x() + 0.02) + c.y(), -0.5};
}

/// Parcels at written time n (index into kTimes); nullopt positions: not present. Identities
/// (origProcId, origId): A (0,0), B (1,0), C (0,1), D (1,1), E (0,2), F (0,3). In the zone (y in
/// [0.01, 0.03] and within the cone): A frames 1-2; B 0, 3, 4; C 1, 3; D 2, 4; E never; F never.
std::vector<TestParcel> parcelsAt(int n) {
  std::vector<TestParcel> out;
  const auto add = [&](double x, double y, std::int32_t proc, std::int32_t id, double d, double count,
                       Eigen::Vector3d u) {
    TestParcel p;
    p.x = {x, y, 0.005};
    p.u = u;
    p.d = d;
    p.nParticle = count;
    p.origProcId = proc;
    p.origId = id;
    out.push_back(p);
  };
  const double yA[] = {0.005, 0.015, 0.025, 0.035, 0.035};
  const double yB[] = {0.02, 0.005, 0.005, 0.015, 0.02};
  const double yC[] = {0.005, 0.015, 0.005, 0.015, 0.005};
  const double yD[] = {0, 0, 0.015, 0.005, 0.015};
  add(-0.005, yA[n], 0, 0, 1.0e-3, 10, {0.1 * n, 1.0, 0.0});
  add(0.004 - 0.001 * n, yB[n], 1, 0, 1.2e-3, 20, {0.0, -1.0, 0.2});
  add(0.003, yC[n], 0, 1, 0.8e-3, 30, {0.3, 0.5, 0.0});
  if (n >= 2) add(0.002, yD[n], 1, 1, 1.1e-3, 40, {0.0, 2.0, 0.0});
  add(0.018, 0.012, 0, 2, 0.9e-3, 50, {1.0, 0.0, 0.0});
  // F shares A's grid cell at frame 0 (x cell 1, y cell 0) with another size, count and velocity.
  add(-0.007, 0.002, 0, 3, 1.5e-3, 5, {-2.0, 4.0, 1.0});
  return out;
}

double parcelVolume(const TestParcel& p) { return p.nParticle * std::numbers::pi * p.d * p.d * p.d / 6.0; }

std::vector<Eigen::Vector3d> cellVelocities(const LatticeMesh& m) {
  std::vector<Eigen::Vector3d> u;
  for (const auto& c : m.cells()) u.push_back(gasVelocity(m.centre(c)));
  return u;
}

/// The gas pressure at written time n: linear in y (so a row's volume mean is its value at the row's
/// centre: 0.005 m for the lowest row, 0.035 m for the highest), odd in x (the rows' means lose it),
/// `gradient(n)` per metre of height. Kinematic [m2/s2] in the reconstructed case, Pa in the decomposed.
double pressureGradient(int n, bool pascal) { return pascal ? 5000.0 + 200.0 * n : 1000.0 + 100.0 * n; }
double pressureAt(const Eigen::Vector3d& c, int n, bool pascal) {
  return (pascal ? 1e5 : 50.0) + 10.0 * n - pressureGradient(n, pascal) * c.y() + 3.0 * c.x();
}
std::vector<double> cellPressures(const LatticeMesh& m, int n, bool pascal) {
  std::vector<double> p;
  for (const auto& c : m.cells()) p.push_back(pressureAt(m.centre(c), n, pascal));
  return p;
}
/// The reconstructed case's gravity (constant/g); the decomposed case has none (9.81 m/s2 is taken).
constexpr double kCaseGravity = 9.5;

class OpenFoamImport : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(testing::TempDir()) / ("openfoam-import-" + std::to_string(::getpid()) + "-" +
                                           testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    scene_ = rcfd::loadScene(sceneDocument(), "test scene");
    scene_.source_json = sceneDocument().dump();
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// The case reconstructed: ASCII mesh, ASCII fields (the gas velocity gzip-compressed at odd
  /// times), ASCII clouds; a 0/ directory with initial conditions only.
  fs::path writeReconstructed(bool identities = true) {
    const fs::path root = dir_ / "reconstructed";
    const LatticeMesh m = latticeMesh();
    m.write(root / "constant/polyMesh", {Encoding::Ascii, false});
    rcfd::test::writeVolVectorField(root / "0/U.air", std::vector<Eigen::Vector3d>(m.cells().size(), Eigen::Vector3d::Zero()),
                                    {Encoding::Ascii, false});
    for (std::size_t n = 0; n < kTimes.size(); ++n) {
      const fs::path t = root / kTimes[n];
      rcfd::test::writeVolVectorField(t / "U.air", cellVelocities(m), {Encoding::Ascii, n % 2 == 1});
      rcfd::test::writeCloud(t / "lagrangian/kinematicCloud", parcelsAt(int(n)), {Encoding::Ascii, n == 2}, identities);
      rcfd::test::writeVolScalarField(t / "p", cellPressures(m, int(n), false), {Encoding::Ascii, n == 3},
                                      "[0 2 -2 0 0 0 0]");
    }
    rcfd::test::writeFoamFile(root / "constant/g",
                              rcfd::test::foamHeader("uniformDimensionedVectorField", "g", Encoding::Ascii) +
                                  "dimensions      [0 1 -2 0 0 0 0];\nvalue           (0 -" + std::to_string(kCaseGravity) +
                                  " 0);\n",
                              false);
    return root;
  }

  /// The same case decomposed: processor0 holds x < 0, processor1 x >= 0; binary files, the clouds'
  /// files gzip-compressed at even times. Parcels are in the processor holding them.
  fs::path writeDecomposed() {
    const fs::path root = dir_ / "decomposed";
    for (int p = 0; p < 2; ++p) {
      LatticeMesh m = latticeMesh();
      m.keep = [p, xs = m.xs](int i, int, int) { return (xs[std::size_t(i)] < 0.0) == (p == 0); };
      const fs::path proc = root / ("processor" + std::to_string(p));
      m.write(proc / "constant/polyMesh", {Encoding::Binary, p == 1});
      for (std::size_t n = 0; n < kTimes.size(); ++n) {
        const fs::path t = proc / kTimes[n];
        rcfd::test::writeVolVectorField(t / "U.air", cellVelocities(m), {Encoding::Binary, false});
        rcfd::test::writeVolScalarField(t / "p", cellPressures(m, int(n), true), {Encoding::Binary, p == 0},
                                        "[1 -1 -2 0 0 0 0]");
        std::vector<TestParcel> mine;
        for (const auto& parcel : parcelsAt(int(n)))
          if ((parcel.x.x() < 0.0) == (p == 0)) mine.push_back(parcel);
        if (!mine.empty())
          rcfd::test::writeCloud(t / "lagrangian/kinematicCloud", mine, {Encoding::Binary, n % 2 == 0});
      }
    }
    return root;
  }

  rcfd::openfoam::ImportResult import(const fs::path& root, const std::string& name,
                                      const std::string& times = "", bool velocitySpread = false) {
    rcfd::openfoam::ImportOptions o;
    o.caseDir = root.string();
    o.databasePath = (dir_ / name).string();
    o.velocitySpread = velocitySpread;
    if (!times.empty()) o.times = rcfd::openfoam::TimeRange::parse(times, "--times");
    return rcfd::openfoam::importOpenFoam(scene_, o);
  }

  fs::path dir_;
  rcfd::Scene scene_;
};

TEST_F(OpenFoamImport, MeshGeometryIsExactForHexCells) {
  const LatticeMesh m = latticeMesh();
  m.write(dir_ / "polyMesh", {Encoding::Binary, true});
  const auto g = rcfd::openfoam::readCellGeometry(dir_ / "polyMesh");
  const auto cells = m.cells();
  ASSERT_EQ(g.cellCount(), std::int64_t(cells.size()));
  for (std::size_t c = 0; c < cells.size(); ++c) {
    EXPECT_NEAR(g.volumes[c], m.volume(cells[c]), 1e-18) << c;
    EXPECT_LT((g.centres[c] - m.centre(cells[c])).norm(), 1e-15) << c;
  }
  EXPECT_NEAR(g.totalVolume(), 0.04 * 0.04 * 0.01, 1e-15);
}

TEST_F(OpenFoamImport, FramesConserveParticleVolumeAndWeightVelocities) {
  const auto result = import(writeReconstructed(), "db.h5");
  auto db = rcfd::FieldDatabase::open((dir_ / "db.h5").string());
  ASSERT_EQ(db->frameCount(), 5);  // 0/ holds initial conditions only and is left out
  EXPECT_NEAR(db->dtRec(), 0.1, 1e-12);
  const auto& g = db->grid();
  ASSERT_EQ(g.shape, (std::array<int, 3>{4, 4, 1}));
  const double cellVolume = g.cellVolume();
  for (int n = 0; n < 5; ++n) {
    const auto f = db->frame(n);
    double expected = 0.0, mapped = 0.0;
    for (const auto& p : parcelsAt(n)) expected += parcelVolume(p);
    for (std::int64_t c = 0; c < g.cellCount(); ++c)
      mapped += double(f->alpha_p[std::size_t(c)]) * cellVolume * double(db->fluidFraction()[std::size_t(c)]);
    EXPECT_NEAR(mapped / expected, 1.0, 1e-6) << "frame " << n;
  }
  // Frame 0: A and F share grid cell (1, 0, 0); u_P is their particle-volume-weighted mean.
  const auto parcels = parcelsAt(0);
  const TestParcel& a = parcels[0];
  const TestParcel& f = parcels.back();
  const std::size_t cell = std::size_t(g.flatIndex(1, 0, 0));
  const Eigen::Vector3d uExpected = (parcelVolume(a) * a.u + parcelVolume(f) * f.u) / (parcelVolume(a) + parcelVolume(f));
  const auto frame0 = db->frame(0);
  for (int d = 0; d < 3; ++d) EXPECT_NEAR(frame0->u_p[3 * cell + std::size_t(d)], uExpected[d], 1e-5) << d;
  EXPECT_NEAR(frame0->alpha_p[cell], (parcelVolume(a) + parcelVolume(f)) / cellVolume, 1e-7);
  EXPECT_LT(result.summary.at("particle_volume").at("max_relative_error").get<double>(), 1e-6);
  EXPECT_EQ(result.summary.at("cloud"), "kinematicCloud");
}

// Asked for (a scene whose tracer effects read it), a Lagrangian cloud's frames carry the velocity spread
// the database job writes: the up-moving share of the particle volume and the two parts' mean velocities,
// which recombine to u_P, and a variance >= 0; the mean fields are those of an import without it.
TEST_F(OpenFoamImport, TheVelocitySpreadOfACloudIsWrittenWhenAskedAndRecombinesToTheMean) {
  const fs::path root = writeReconstructed();
  const auto with = import(root, "spread.h5", "", true);
  import(root, "plain.h5");
  EXPECT_TRUE(with.summary.at("velocity_spread").get<bool>());
  auto spread = rcfd::FieldDatabase::open((dir_ / "spread.h5").string(), rcfd::FrameStorage{0, true});
  auto plain = rcfd::FieldDatabase::open((dir_ / "plain.h5").string());
  ASSERT_TRUE(spread->hasVelocitySpread());
  EXPECT_FALSE(plain->hasVelocitySpread());
  const auto& g = spread->grid();
  for (int n = 0; n < spread->frameCount(); ++n) {
    const auto f = spread->frame(n), q = plain->frame(n);
    EXPECT_EQ(f->alpha_p, q->alpha_p) << n;
    EXPECT_EQ(f->u_p, q->u_p) << n;
    for (std::int64_t c = 0; c < g.cellCount(); ++c) {
      const std::size_t i = std::size_t(c);
      if (!(f->alpha_p[i] > 0.0f)) continue;
      const double share = f->up_fraction[i];
      EXPECT_GE(share, 0.0);
      EXPECT_LE(share, 1.0);
      for (std::size_t d = 0; d < 3; ++d) {
        EXPECT_NEAR(share * f->u_p_up[3 * i + d] + (1.0 - share) * f->u_p_down[3 * i + d], f->u_p[3 * i + d], 1e-5)
            << "frame " << n << " cell " << c;
        EXPECT_GE(f->u_p_variance[3 * i + d], 0.0f);
      }
    }
  }
  // Frame 0: A and F share grid cell (1, 0, 0); the up share is the volume of those rising.
  const auto parcels = parcelsAt(0);
  const TestParcel& a = parcels[0];
  const TestParcel& b = parcels.back();
  const double rising = (a.u.y() > 0.0 ? parcelVolume(a) : 0.0) + (b.u.y() > 0.0 ? parcelVolume(b) : 0.0);
  const std::size_t cell = std::size_t(g.flatIndex(1, 0, 0));
  EXPECT_NEAR(spread->frame(0)->up_fraction[cell], rising / (parcelVolume(a) + parcelVolume(b)), 1e-6);
  // Without a cloud's parcels there is no spread to write: an import not asked writes none either.
  EXPECT_FALSE(import(root, "again.h5").summary.at("velocity_spread").get<bool>());
}

TEST_F(OpenFoamImport, GasVelocityIsTheVolumeWeightedMeanOverTheCell) {
  import(writeReconstructed(), "db.h5");
  auto db = rcfd::FieldDatabase::open((dir_ / "db.h5").string());
  const auto& g = db->grid();
  const LatticeMesh m = latticeMesh();
  std::map<std::int64_t, std::pair<double, Eigen::Vector3d>> sums;
  for (const auto& c : m.cells()) {
    auto& s = sums.try_emplace(g.flatIndexOf(m.centre(c)), 0.0, Eigen::Vector3d::Zero()).first->second;
    s.first += m.volume(c);
    s.second += m.volume(c) * gasVelocity(m.centre(c));
  }
  ASSERT_EQ(std::int64_t(sums.size()), g.cellCount());
  const auto f = db->frame(3);
  for (const auto& [cell, s] : sums) {
    const Eigen::Vector3d mean = s.second / s.first;
    for (int d = 0; d < 3; ++d) EXPECT_NEAR(f->u_g[3 * std::size_t(cell) + std::size_t(d)], mean[d], 2e-6) << cell;
    // The x component is linear: its mean is its value at the grid cell's centre.
    const auto ijk = g.cellIjk(cell);
    EXPECT_NEAR(f->u_g[3 * std::size_t(cell)], gasVelocity(g.cellCenter(ijk[0], ijk[1], ijk[2])).x(), 2e-6);
  }
}

TEST_F(OpenFoamImport, ReferenceHoldsTheSprayZoneStaysAndHoldupAsConstructed) {
  const auto result = import(writeReconstructed(), "db.h5");
  const auto ref = rcfd::analysis::readReferenceStatistics((dir_ / "db.h5").string());
  // Completed stays: A frames 1-2 (2 frames), C frame 1 and frame 3 (1 frame each); B's first stay is
  // open at the start, B's and D's last ones at the end, D's first entry unseen.
  ASSERT_EQ(ref.durations.size(), 3u);
  EXPECT_NEAR(ref.durations[0], 0.1, 1e-12);
  EXPECT_NEAR(ref.durations[1], 0.1, 1e-12);
  EXPECT_NEAR(ref.durations[2], 0.2, 1e-12);
  EXPECT_NEAR(ref.durationsDt, 0.1, 1e-12);
  EXPECT_EQ(ref.members, 6.0);
  EXPECT_NEAR(ref.period, 0.5, 1e-12);
  // Holdup in real particles (nParticle of the parcels inside): B; A + C; A + D; B + C; B + D.
  const std::vector<double> particles = {20, 40, 50, 50, 60};
  ASSERT_EQ(ref.holdup.size(), particles.size());
  for (std::size_t n = 0; n < particles.size(); ++n) EXPECT_EQ(ref.holdup[n], particles[n]) << n;
  EXPECT_NEAR(ref.holdupDt, 0.1, 1e-12);
  rcfd::h5::File f((dir_ / "db.h5").string(), rcfd::h5::File::Mode::ReadOnly);
  EXPECT_EQ(f.readDoubles(rcfd::reference_series::holdupParcels), (std::vector<double>{1, 2, 2, 2, 2}));
  EXPECT_EQ(result.summary.at("reference").at("residence_time").at("censored"), 2);  // B and D inside at the end
}

// The bed pressure drop of the database job: the lowest row's pressure less the highest row's, less
// the gas's head between the rows' centres (0.03 m apart); a kinematic p times the scene's gas density.
TEST_F(OpenFoamImport, PressureDropIsTheRowsDifferenceLessTheGasHead) {
  const double rho = scene_.gas.density, rise = 0.03;
  for (const bool pascal : {false, true}) {
    SCOPED_TRACE(pascal ? "decomposed, p in Pa, no constant/g" : "reconstructed, kinematic p, constant/g");
    const fs::path root = pascal ? writeDecomposed() : writeReconstructed();
    const auto r = import(root, pascal ? "pa.h5" : "kinematic.h5");
    const json& dp = r.summary.at("reference").at("pressure_drop");
    ASSERT_TRUE(dp.is_object()) << r.summary.dump(2);
    EXPECT_EQ(dp.at("field"), "p");
    EXPECT_EQ(dp.at("kinematic"), !pascal);
    EXPECT_EQ(dp.at("samples"), kTimes.size());
    rcfd::h5::File db((dir_ / (pascal ? "pa.h5" : "kinematic.h5")).string(), rcfd::h5::File::Mode::ReadOnly);
    const std::vector<double> series = db.readDoubles(rcfd::reference_series::pressureDrop);
    ASSERT_EQ(series.size(), kTimes.size());
    double mean = 0.0;
    for (std::size_t n = 0; n < series.size(); ++n) {
      const double g = pascal ? 9.81 : kCaseGravity;
      const double expected = (pascal ? 1.0 : rho) * pressureGradient(int(n), pascal) * rise - rho * g * rise;
      EXPECT_NEAR(series[n], expected, 1e-9 * std::abs(expected) + 1e-9) << "frame " << n;
      mean += expected / double(series.size());
    }
    EXPECT_NEAR(dp.at("mean_pa").get<double>(), mean, 1e-9 * std::abs(mean));
    EXPECT_DOUBLE_EQ(db.doubleAttribute(rcfd::reference_series::pressureDrop, "dt"), 0.1);
  }
}

TEST_F(OpenFoamImport, APressureInOtherUnitsIsRefusedNamingItsDimensions) {
  const fs::path root = writeReconstructed();
  const LatticeMesh m = latticeMesh();
  rcfd::test::writeVolScalarField(root / "0.3/p", cellPressures(m, 2, false), {Encoding::Ascii, false}, "[0 1 -2 0 0]");
  try {
    import(root, "units.h5", "0.1:0.3");
    ADD_FAILURE() << "a pressure in m/s2 was accepted";
  } catch (const rcfd::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("0.3/p"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("dimensions"), std::string::npos) << e.what();
  }
  rcfd::test::writeVolScalarField(root / "0.3/p", cellPressures(m, 2, false), {Encoding::Ascii, false},
                                  "[1 -1 -2 0 0 0 0]");
  try {
    import(root, "mixed.h5", "0.1:0.3");
    ADD_FAILURE() << "kinematic and Pa pressures in one case were accepted";
  } catch (const rcfd::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("differ from those of the first time"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir_ / "units.h5"));
}

TEST_F(OpenFoamImport, DecomposedBinaryCaseGivesTheReconstructedDatabase) {
  import(writeReconstructed(), "reconstructed.h5");
  const auto result = import(writeDecomposed(), "decomposed.h5");
  EXPECT_TRUE(result.summary.at("decomposed").get<bool>());
  EXPECT_EQ(result.summary.at("parts"), 2);
  auto a = rcfd::FieldDatabase::open((dir_ / "reconstructed.h5").string());
  auto b = rcfd::FieldDatabase::open((dir_ / "decomposed.h5").string());
  ASSERT_EQ(a->frameCount(), b->frameCount());
  for (int n = 0; n < a->frameCount(); ++n) {
    const auto fa = a->frame(n), fb = b->frame(n);
    for (std::size_t i = 0; i < fa->alpha_p.size(); ++i) EXPECT_NEAR(fa->alpha_p[i], fb->alpha_p[i], 1e-7);
    for (std::size_t i = 0; i < fa->u_p.size(); ++i) EXPECT_NEAR(fa->u_p[i], fb->u_p[i], 1e-5);
    for (std::size_t i = 0; i < fa->u_g.size(); ++i) EXPECT_NEAR(fa->u_g[i], fb->u_g[i], 1e-5);
  }
  const auto ra = rcfd::analysis::readReferenceStatistics((dir_ / "reconstructed.h5").string());
  const auto rb = rcfd::analysis::readReferenceStatistics((dir_ / "decomposed.h5").string());
  EXPECT_EQ(ra.durations, rb.durations);
  EXPECT_EQ(ra.holdup, rb.holdup);
}

TEST_F(OpenFoamImport, TimeRangeSelectsFrames) {
  import(writeReconstructed(), "db.h5", "0.2:0.4");
  auto db = rcfd::FieldDatabase::open((dir_ / "db.h5").string());
  EXPECT_EQ(db->frameCount(), 3);
  const auto ref = rcfd::analysis::readReferenceStatistics((dir_ / "db.h5").string());
  // Over 0.2-0.4, A's and C's stays are open at 0.2 (the first sight: entry unknown), D's at its
  // first sight, B's and C's last ones at 0.4: no completed stay.
  EXPECT_TRUE(ref.durations.empty());
  EXPECT_EQ(ref.holdup, (std::vector<double>{40, 50, 50}));
}

TEST_F(OpenFoamImport, WithoutIdentitiesOnlyTheHoldupIsWritten) {
  const auto result = import(writeReconstructed(false), "db.h5");
  const auto ref = rcfd::analysis::readReferenceStatistics((dir_ / "db.h5").string());
  EXPECT_FALSE(ref.hasDurations());
  EXPECT_TRUE(ref.hasHoldup());
  EXPECT_TRUE(result.summary.at("reference").contains("residence_time_missing"));
}

TEST_F(OpenFoamImport, EulerianParticlePhaseIsMappedByVolume) {
  const fs::path root = dir_ / "eulerian";
  const LatticeMesh m = latticeMesh();
  m.write(root / "constant/polyMesh", {Encoding::Binary, false});
  double total = 0.0;
  std::vector<double> alpha;
  std::vector<Eigen::Vector3d> up;
  for (const auto& c : m.cells()) {
    alpha.push_back(0.1 + 0.5 * (c[0] + 2 * c[1] + 3 * c[2]) / 30.0);
    up.push_back({double(c[0]), double(c[1]), 0.0});
    total += alpha.back() * m.volume(c);
  }
  for (const std::string t : {"1", "2", "3"}) {
    rcfd::test::writeVolVectorField(root / t / "U.air", cellVelocities(m), {Encoding::Binary, true});
    rcfd::test::writeVolScalarField(root / t / "alpha.particles", alpha, {Encoding::Binary, false});
    rcfd::test::writeVolVectorField(root / t / "U.particles", up, {Encoding::Ascii, false});
  }
  const auto result = import(root, "db.h5");
  EXPECT_EQ(result.summary.at("particle_source"), "eulerian");
  auto db = rcfd::FieldDatabase::open((dir_ / "db.h5").string());
  const auto f = db->frame(1);
  double mapped = 0.0;
  for (std::int64_t c = 0; c < db->grid().cellCount(); ++c)
    mapped += double(f->alpha_p[std::size_t(c)]) * db->grid().cellVolume() * double(db->fluidFraction()[std::size_t(c)]);
  EXPECT_NEAR(mapped / total, 1.0, 1e-6);
  // Grid cell (0, 0, 0) holds mesh cells i, j in {0, 1}, k in {0, 1}: u_P,x is their alpha V weighted i.
  double w = 0.0, wx = 0.0;
  for (const auto& c : m.cells())
    if (c[0] < 2 && c[1] < 2) {
      const double a = 0.1 + 0.5 * (c[0] + 2 * c[1] + 3 * c[2]) / 30.0;
      w += a * m.volume(c);
      wx += a * m.volume(c) * c[0];
    }
  EXPECT_NEAR(f->u_p[0], wx / w, 1e-6);
  EXPECT_FALSE(rcfd::h5::File((dir_ / "db.h5").string(), rcfd::h5::File::Mode::ReadOnly).exists("/reference"));
  EXPECT_TRUE(result.summary.at("reference").at("pressure_drop").is_null());
  EXPECT_NE(result.summary.at("reference").at("pressure_drop_missing").get<std::string>().find("writes no p"),
            std::string::npos);
}

// --- malformed input: an InputError naming the file and what was expected ---

std::string importError(const std::function<void()>& f) {
  try {
    f();
  } catch (const rcfd::InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

TEST_F(OpenFoamImport, MalformedFilesAreInputErrorsNamingFileAndEntry) {
  const fs::path root = writeReconstructed();
  const fs::path field = root / "0.3/U.air";
  const auto expectMessage = [&](const std::string& text, std::initializer_list<std::string> parts) {
    rcfd::test::writeFoamFile(field, text, false);
    const std::string message = importError([&] { import(root, "bad.h5"); });
    for (const auto& part : parts) EXPECT_NE(message.find(part), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(dir_ / "bad.h5"));
    EXPECT_FALSE(fs::exists(dir_ / "bad.h5.partial"));
  };
  const std::string header = rcfd::test::foamHeader("volVectorField", "U.air", Encoding::Ascii);
  expectMessage("not an OpenFOAM file", {"0.3/U.air", "FoamFile"});
  expectMessage(header + "internalField nonuniform List<vector> 3 ((1 2 3) (4 5 6) (7 8 9));", {"0.3/U.air", "internalField", "128 cells"});
  expectMessage(header + "internalField nonuniform List<vector> 128 ((1 2 3) (4 5 x)", {"0.3/U.air", "internalField", "expected a number", "\"x\""});
  expectMessage(header + "internalField sometimes (1 2 3);", {"internalField", "uniform or nonuniform"});
  expectMessage(header + "dimensions [0 1 -1 0 0 0 0];\n", {"0.3/U.air", "no internalField"});
  const std::string binary = rcfd::test::foamHeader("volVectorField", "U.air", Encoding::Binary);
  expectMessage(binary + "internalField nonuniform List<vector> 128(" + std::string(100, '\0'), {"internalField", "runs past the end"});
  fs::remove(field);
  EXPECT_NE(importError([&] { import(root, "bad.h5"); }).find("0.3/U.air"), std::string::npos);
}

TEST_F(OpenFoamImport, BarycentricCoordinatesOnlyNameTheFix) {
  const fs::path root = writeReconstructed();
  const fs::path cloud = root / "0.3/lagrangian/kinematicCloud";
  fs::rename(cloud / "positions.gz", cloud / "coordinates.gz");  // time 0.3's cloud was written compressed
  const std::string message = importError([&] { import(root, "db.h5"); });
  EXPECT_NE(message.find("coordinates"), std::string::npos) << message;
  EXPECT_NE(message.find("writeLagrangianPositions"), std::string::npos) << message;
}

TEST_F(OpenFoamImport, UnevenTimesAndTooFewTimesAreRefused) {
  const fs::path root = writeReconstructed();
  fs::rename(root / "0.5", root / "0.55");
  EXPECT_NE(importError([&] { import(root, "db.h5"); }).find("not evenly spaced"), std::string::npos);
  EXPECT_NE(importError([&] { import(root, "db.h5", "0.1:0.2"); }).find("at least 3"), std::string::npos);
  EXPECT_THROW(rcfd::openfoam::TimeRange::parse("0.1-0.2", "--times"), rcfd::InputError);
}

TEST_F(OpenFoamImport, ParserReadsUniformListsCommentsAndLabel64) {
  auto f = rcfd::openfoam::FoamFile::fromText(
      "/* banner */ FoamFile { format ascii; class scalarField; object d; } // comment\n 4{2.5e-3}", "d");
  EXPECT_EQ(f.scalarList("d"), (std::vector<double>(4, 2.5e-3)));
  std::string text = "FoamFile { format binary; arch \"LSB;label=64;scalar=64\"; class labelList; }\n2(";
  const std::int64_t labels[2] = {7, 5000000000LL};
  text.append(reinterpret_cast<const char*>(labels), sizeof labels);
  text += ")";
  auto g = rcfd::openfoam::FoamFile::fromText(text, "owner");
  EXPECT_EQ(g.labelList("owner"), (std::vector<std::int64_t>{7, 5000000000LL}));
  // Subnormal values, as OpenFOAM writes them, are numbers.
  auto h = rcfd::openfoam::FoamFile::fromText("FoamFile { format ascii; }\n2(9.0320351e-42 1)", "U");
  EXPECT_EQ(h.scalarList("U").size(), 2u);
}

}  // namespace

namespace {

TEST_F(OpenFoamImport, ImportJobWritesDatabaseResultAndSummary) {
  const fs::path root = writeReconstructed();
  rcfd::JobSpec job;
  job.kind = "import";
  job.scene = scene_;
  job.source = {{"kind", "import"}, {"scene", sceneDocument()}, {"case_dir", root.string()}, {"times", "0.1:0.4"}};
  rcfd::RunOptions options;
  options.outDir = (dir_ / "job").string();
  const json summary = rcfd::runJob(job, options);
  EXPECT_EQ(summary.at("kind"), "import");
  EXPECT_EQ(summary.at("frames"), 4);
  EXPECT_EQ(json::parse(std::ifstream(dir_ / "job/summary.json")).at("database"), "database.h5");
  auto db = rcfd::FieldDatabase::open((dir_ / "job/database.h5").string());
  EXPECT_EQ(db->frameCount(), 4);
  rcfd::h5::File result((dir_ / "job/result.h5").string(), rcfd::h5::File::Mode::ReadOnly);
  EXPECT_EQ(result.readDoubles("/fields/alpha_p_mean").size(), 16u);
  // ParaView opens both files through their sidecars (tests/paraview checks what it shows).
  EXPECT_TRUE(fs::exists(dir_ / "job/database.xmf"));
  EXPECT_TRUE(fs::exists(dir_ / "job/result.xmf"));
  EXPECT_EQ(summary.at("figures"), json({"database_alpha_p.svg", "database_pressure_drop.svg"}));
  for (const auto& f : summary.at("figures")) EXPECT_TRUE(fs::exists(dir_ / "job" / f.get<std::string>())) << f;
}

TEST_F(OpenFoamImport, JobSchemaTakesImportKeysOnlyForImportJobs) {
  json job = {{"kind", "import"}, {"scene", sceneDocument()}, {"case_dir", "case"}, {"times", "1:2"}};
  EXPECT_EQ(rcfd::loadJob(job).kind, "import");
  job.erase("case_dir");
  EXPECT_THROW(rcfd::loadJob(job), rcfd::InputError);
  json spray = {{"kind", "spray"}, {"scene", sceneDocument()}, {"database", "db.h5"}, {"duration", 1.0},
                {"case_dir", "case"}};
  try {
    rcfd::loadJob(spray);
    ADD_FAILURE() << "a spray job with case_dir was accepted";
  } catch (const rcfd::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("only import jobs take"), std::string::npos) << e.what();
  }
}

}  // namespace
