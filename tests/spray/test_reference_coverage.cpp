// The full simulation's reference coverage (spray/ReferenceCoverage.hpp) is the tracer run's spray model
// on other members: given the positions a tracer run holds, it must hand out exactly the droplets that
// run hands out; it must resume bit for bit; and the comparison of two coverage distributions
// (analysis/CoverageComparison.hpp) must report what it finds and refuse what it cannot compare.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "analysis/CoverageComparison.hpp"
#include "analysis/ReferenceStatistics.hpp"
#include "core/Errors.hpp"
#include "core/Hdf5.hpp"
#include "spray/Coverage.hpp"
#include "spray/ReferenceCoverage.hpp"
#include "spray/SprayState.hpp"
#include "SprayTestSupport.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {

/// A box bed at rest below y = 0.08 m with a rising gas, 400 members of 8 particles each (the
/// reference's cg = 2), sprayed from the floor.
struct RestingBed {
  Scene scene = sprayBoxScene(400, 0.3, 0.08);
  std::shared_ptr<FieldDatabase> db;
  std::unique_ptr<Apparatus> apparatus;
  RestingBed() {
    scene.effects = {"tracer_volume_fraction", "spray", "deposition", "coverage"};
    scene.dem.coarse_graining = 2.0;
    const double particle = std::numbers::pi / 6.0 * std::pow(scene.particles.diameter, 3);
    scene.process.bed_mass = 8.0 * 400 * particle * scene.particles.density;
    db = sprayBoxDatabase(scene, 0.3, 0.08, 3.0);
    apparatus = std::make_unique<Apparatus>(scene.apparatus);
  }
};

/// The positions and ids of a tracer cloud, as the database job hands the parcels over.
struct Parcels {
  std::vector<Eigen::Vector3d> x;
  std::vector<std::uint64_t> id;
  std::size_t size() const { return x.size(); }
};
Parcels parcelsAt(const TracerCloud& cloud) {
  Parcels p;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    p.x.push_back(cloud.position(i));
    p.id.push_back(std::uint64_t(cloud.id[i]));
  }
  return p;
}

ReferenceCoverage makeReference(const RestingBed& bed, std::size_t parcels) {
  const auto& fluid = bed.db->fluidFraction();
  return ReferenceCoverage(bed.scene, *bed.apparatus, bed.db->grid(), std::vector<double>(fluid.begin(), fluid.end()),
                           parcels, bed.scene.rcfd.dt, 3);
}

}  // namespace

TEST(ReferenceCoverage, HandsOutExactlyTheDropletsOfATracerRunOnTheSamePositions) {
  RestingBed bed;
  const std::int64_t steps = 400;
  TracerRunSettings settings{3, steps, 0};
  settings.sortInterval = 0;  // index order = id order on both sides: the hand-out within a cell follows it
  TracerSimulation sim(bed.scene, bed.db, sequentialPath(bed.db->frameCount(), steps + 2), settings);
  ASSERT_NEAR(sim.cloud().particlesPerTracer, 8.0, 1e-9);
  const Parcels parcels = parcelsAt(sim.cloud());
  ReferenceCoverage ref = makeReference(bed, parcels.size());
  for (std::int64_t k = 0; k < steps; ++k) {
    ref.step(parcels.x, parcels.id, sim.context().frame);  // the frame of the tracer run's step k
    sim.step();
  }
  EXPECT_EQ(ref.steps(), steps);
  EXPECT_DOUBLE_EQ(ref.duration(), double(steps) * bed.scene.rcfd.dt);
  const auto perParticle = ref.dropletsPerParticle();
  const auto& collected = sim.context().spray->tracerDroplets;
  ASSERT_EQ(perParticle.size(), collected.size());
  double total = 0.0;
  for (std::size_t i = 0; i < collected.size(); ++i) {
    EXPECT_DOUBLE_EQ(perParticle[std::size_t(sim.cloud().id[i])] * 8.0, collected[i]) << "member " << i;
    total += collected[i];
  }
  EXPECT_GT(total, 1000.0);  // the spray reached the bed: the equality is not one of zeros
  const auto summary = ref.summary();
  EXPECT_EQ(summary["parcels"].get<std::size_t>(), parcels.size());
  EXPECT_DOUBLE_EQ(summary["particles_per_parcel"].get<double>(), 8.0);
  EXPECT_GT(summary["mean"].get<double>(), 0.0);
  const auto& b = sim.context().spray->balance;
  EXPECT_NEAR(summary["deposited_fraction"].get<double>(), b.deposited / b.injected, 1e-12);
}

TEST(ReferenceCoverage, SavedAndLoadedMidwayEqualsUninterrupted) {
  RestingBed bed;
  TracerRunSettings settings{3, 10, 0};
  TracerSimulation placement(bed.scene, bed.db, sequentialPath(bed.db->frameCount(), 12), settings);
  const Parcels parcels = parcelsAt(placement.cloud());
  auto frame = [&](std::int64_t k) { return bed.db->frame(int(k % bed.db->frameCount())); };
  ReferenceCoverage whole = makeReference(bed, parcels.size());
  for (std::int64_t k = 0; k < 300; ++k) whole.step(parcels.x, parcels.id, frame(k));
  const std::string path = tempPath("reference-coverage-state.h5");
  {
    ReferenceCoverage first = makeReference(bed, parcels.size());
    for (std::int64_t k = 0; k < 137; ++k) first.step(parcels.x, parcels.id, frame(k));
    h5::File f(path, h5::File::Mode::Create);
    first.save(f, "/state");
  }
  ReferenceCoverage resumed = makeReference(bed, parcels.size());
  {
    h5::File f(path, h5::File::Mode::ReadOnly);
    resumed.load(f, "/state");
  }
  EXPECT_EQ(resumed.steps(), 137);
  for (std::int64_t k = 137; k < 300; ++k) resumed.step(parcels.x, parcels.id, frame(k));
  EXPECT_EQ(resumed.dropletsPerParticle(), whole.dropletsPerParticle());
  EXPECT_EQ(resumed.summary().dump(), whole.summary().dump());
  std::filesystem::remove(path);
}

TEST(ReferenceCoverage, WrittenIntoTheDatabaseAndReadBack) {
  RestingBed bed;
  TracerSimulation placement(bed.scene, bed.db, sequentialPath(bed.db->frameCount(), 12), {3, 10, 0});
  const Parcels parcels = parcelsAt(placement.cloud());
  ReferenceCoverage ref = makeReference(bed, parcels.size());
  for (std::int64_t k = 0; k < 200; ++k) ref.step(parcels.x, parcels.id, bed.db->frame(int(k % bed.db->frameCount())));
  const std::string path = tempPath("reference-coverage-db.h5");
  {
    h5::File f(path, h5::File::Mode::Create);
    ref.write(f);
  }
  const auto back = analysis::readReferenceCoverage(path);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->dropletsPerParticle, ref.dropletsPerParticle());
  EXPECT_DOUBLE_EQ(back->duration, 200 * bed.scene.rcfd.dt);
  EXPECT_DOUBLE_EQ(back->particlesPerParcel, 8.0);
  EXPECT_DOUBLE_EQ(back->singleDropletCoverage,
                   singleDropletCoverage(bed.scene.spray.droplet_diameter, bed.scene.particles.diameter));
  // The books close: injected = deposited + airborne + overspray + residual.
  h5::File f(path, h5::File::Mode::ReadOnly);
  const auto books = f.readDoubles(analysis::reference_layout::coverageBalance);
  ASSERT_EQ(books.size(), 6u);
  EXPECT_NEAR(books[0], books[1] + books[2] + books[3] + books[4] + books[5], 1e-9 * books[0]);
  EXPECT_GT(books[1], 0.0);
  std::filesystem::remove(path);
}

TEST(CoverageComparison, IdenticalDistributionsAgreeAndAShiftedOneDoesNot) {
  analysis::ReferenceCoverageData ref;
  for (int i = 0; i < 1000; ++i) ref.dropletsPerParticle.push_back(double(i % 50));
  ref.duration = 2.0, ref.dt = 0.001, ref.particlesPerParcel = 8.0, ref.singleDropletCoverage = 0.01;
  const auto same = analysis::compareCoverage(ref.dropletsPerParticle, 8.0, 2.0, 0.005, 0.01, ref);
  EXPECT_TRUE(same.sameDuration);
  EXPECT_EQ(same.ksDistance, 0.0);
  const auto j = same.toJson();
  EXPECT_EQ(j["mean_relative_error"].get<double>(), 0.0);
  EXPECT_FALSE(j.contains("note"));
  // Every member 10 droplets more: the whole distribution moves, by a KS distance of 10/50.
  std::vector<double> more = ref.dropletsPerParticle;
  for (double& v : more) v += 10.0;
  const auto shifted = analysis::compareCoverage(more, 8.0, 2.0, 0.005, 0.01, ref);
  EXPECT_NEAR(shifted.ksDistance, 0.2, 1e-12);
  EXPECT_GT(shifted.toJson()["mean_relative_error"].get<double>(), 0.1);
  EXPECT_NEAR(shifted.run.dropletsPerParticleMean - shifted.reference.dropletsPerParticleMean, 10.0, 1e-12);
  // Coverage follows Eq. (15).
  EXPECT_NEAR(same.reference.mean, [&] {
    double s = 0.0;
    for (double n : ref.dropletsPerParticle) s += 1.0 - std::pow(0.99, n);
    return s / 1000.0;
  }(), 1e-12);
}

TEST(CoverageComparison, SaysWhatItCannotCompare) {
  analysis::ReferenceCoverageData ref;
  ref.dropletsPerParticle = {1.0, 2.0, 3.0};
  ref.duration = 2.0, ref.dt = 0.001, ref.particlesPerParcel = 8.0, ref.singleDropletCoverage = 0.01;
  // Another duration: no distance, a note.
  const auto longer = analysis::compareCoverage({1.0, 2.0}, 8.0, 600.0, 0.005, 0.01, ref).toJson();
  EXPECT_FALSE(longer["same_duration"].get<bool>());
  EXPECT_FALSE(longer.contains("ks_distance"));
  EXPECT_TRUE(longer.contains("note"));
  // Tracers standing for 5 x the particles of a parcel: compared, with a note.
  const auto coarse = analysis::compareCoverage({1.0, 2.0}, 40.0, 2.0, 0.005, 0.01, ref).toJson();
  EXPECT_TRUE(coarse.contains("ks_distance"));
  EXPECT_TRUE(coarse.contains("note"));
  // Another droplet size: not comparable at all.
  EXPECT_THROW(analysis::compareCoverage({1.0}, 8.0, 2.0, 0.005, 0.02, ref), InputError);
}

TEST(CoverageComparison, AMalformedReferenceIsAnErrorNamingTheDataset) {
  const std::string path = tempPath("reference-coverage-bad.h5");
  {
    h5::File f(path, h5::File::Mode::Create);
    f.write("/frames/alpha_p", std::vector<double>{0.0});
  }
  EXPECT_FALSE(analysis::readReferenceCoverage(path).has_value());  // none: nothing to compare
  // Reading the file is an InputError whose message names `mention`.
  auto expectRefusal = [&](const std::string& what, const std::string& mention) {
    try {
      analysis::readReferenceCoverage(path);
      ADD_FAILURE() << what << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(mention), std::string::npos) << e.what();
    }
  };
  {
    h5::File f(path, h5::File::Mode::ReadWrite);
    f.write(analysis::reference_layout::coverageDroplets, std::vector<double>{1.0, -2.0});
  }
  expectRefusal("a negative droplet count", "droplets_per_particle");
  std::filesystem::remove(path);
  {
    h5::File f(path, h5::File::Mode::Create);
    f.write(analysis::reference_layout::coverageDroplets, std::vector<double>{1.0, 2.0});
  }
  expectRefusal("missing attributes", "duration_s");
  std::filesystem::remove(path);
}
