// Spray-zone stays of the tracers against the particles' on a database written from an analytic particle
// motion whose stays are known in closed form: solid-body rotation. Particles fill a disk of radius R
// about the box's centre at alpha_P = alpha0 and turn at a constant angular speed omega; the spray zone
// is a horizontal band above the centre, across the whole box. For the paper's tracer model ("mean":
// Eq. (9) with Eq. (10)'s random walk, at D0 = 0 and at a small D0) and for the Langevin model
// (directed_relaxation + langevin_velocity, without and with the velocity spread a cell of the
// rotation holds), the tracers' mean stay, crossing rate and stay distribution (analysis::compareStays,
// on the tracers' step lattice and window) and their mean zone holdup must match the exact ones; every
// tracer stays inside the box and none is lost. A reference of another rotation rate or band fails the
// same bounds. A disk whose particles also fluctuate keeps the Langevin tracers within it.
//
// Why this case: u_P = omega x (p - centre) is linear, so inside the disk the trilinear interpolation
// between cell centres reproduces it exactly and the midpoint rule keeps the tracers on their circles
// (the database reader replaces u_P of the cells without particle volume by its completion, which only
// the disk's rim reaches); a particle on radius r crosses the band in a time given by arcsines of the
// band's edges over r, so the whole reference follows from the disk's area-uniform radii without any
// sampling of a simulation. What the comparison then measures is the tracer model, not the database or
// the reference.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include <nlohmann/json.hpp>

#include "TracerTestSupport.hpp"
#include "analysis/StayComparison.hpp"
#include "geometry/SprayZone.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {

constexpr double kPi = std::numbers::pi;

/// Particles turning as a rigid disk about (centreX, centreY) at omega (counter-clockwise), filling
/// r <= radius at alpha0 and nothing outside. The spray zone is the band bandLow <= y - centreY <=
/// bandHigh (0 < bandLow < bandHigh < radius).
struct SolidBodyRotation {
  double omega = 5.0;      ///< [rad/s]: the rim moves at 0.4 m/s
  double centreX = 0.0, centreY = 0.1;  ///< [m], the middle of the 0.2 m x 0.2 m box
  double radius = 0.08;    ///< R [m]
  double alpha0 = 0.3;     ///< alpha_P inside the disk [-]
  double bandLow = 0.03;   ///< lower edge of the zone above the centre [m]
  double bandHigh = 0.06;  ///< upper edge of the zone above the centre [m]
  /// Whether the frames hold the velocity spread a cell of the rotation holds: u_P varies linearly
  /// across the cell, so each in-plane component varies about the cell's mean with variance omega^2
  /// h^2 / 12 (h the cell's extent across it). Without, the variance is 0: each particle moves with the
  /// mean velocity at its own position, which the interpolation already gives the tracers.
  bool cellSpread = false;
  /// An isotropic velocity variance [m2/s2] added in every cell holding particles: a disk whose
  /// particles also fluctuate about the rotation (a granular temperature), confined to the disk.
  double thermalVariance = 0.0;

  double revolution() const { return 2.0 * kPi / omega; }

  /// The stays of a particle on radius r in one revolution [s]: two side passes (up on the right, down
  /// on the left) when the circle reaches above the band, one pass over the top when its top lies in
  /// the band, none when the circle stays below it.
  std::vector<double> staysPerRevolution(double r) const {
    if (r > bandHigh) {
      const double pass = (std::asin(bandHigh / r) - std::asin(bandLow / r)) / omega;
      return {pass, pass};
    }
    if (r > bandLow) return {(kPi - 2.0 * std::asin(bandLow / r)) / omega};
    return {};
  }

  /// Area of the disk between heights 0 and y above its centre (0 <= y <= R).
  double diskAreaBelow(double y) const {
    return y * std::sqrt(radius * radius - y * y) + radius * radius * std::asin(y / radius);
  }
  /// Area of the band inside the disk [m2]: the exact holdup is alpha0 times it times the depth.
  double bandAreaInDisk() const { return diskAreaBelow(bandHigh) - diskAreaBelow(bandLow); }
  double diskArea() const { return kPi * radius * radius; }

  /// The steady frame: alpha_P = alpha0 times the cell's area fraction inside the disk (16 x 16
  /// sub-samples, so the particle volume is the disk's to the sampling's accuracy), u_P = u_G = the
  /// rotation at the cell centre, and the velocity spread of a rigid rotation: each cell wholly rising
  /// or falling (x = 0 is a cell face), its variance that of cellSpread where it holds particles.
  void fill(const CartesianGrid& grid, FieldFrame& f) const {
    const std::size_t cells = std::size_t(grid.cellCount());
    zeroVelocitySpread(f, cells);
    constexpr int kSub = 16;
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      const Eigen::Vector3d centre = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
      int samplesInside = 0;
      for (int a = 0; a < kSub; ++a) {
        for (int b = 0; b < kSub; ++b) {
          const double x = centre.x() + grid.spacing.x() * ((a + 0.5) / kSub - 0.5) - centreX;
          const double y = centre.y() + grid.spacing.y() * ((b + 0.5) / kSub - 0.5) - centreY;
          samplesInside += x * x + y * y <= radius * radius;
        }
      }
      const std::size_t i = std::size_t(c);
      f.alpha_p[i] = float(alpha0 * samplesInside / double(kSub * kSub));
      const double ux = -omega * (centre.y() - centreY), uy = omega * (centre.x() - centreX);
      for (auto* v : {&f.u_p, &f.u_g, &f.u_p_up, &f.u_p_down}) {
        (*v)[3 * i] = float(ux);
        (*v)[3 * i + 1] = float(uy);
      }
      f.up_fraction[i] = uy > 0.0 ? 1.0f : 0.0f;
      if (cellSpread && samplesInside > 0) {
        f.u_p_variance[3 * i] = float(omega * omega * grid.spacing.y() * grid.spacing.y() / 12.0);
        f.u_p_variance[3 * i + 1] = float(omega * omega * grid.spacing.x() * grid.spacing.x() / 12.0);
      }
      if (samplesInside > 0) {
        for (int d = 0; d < 3; ++d) f.u_p_variance[3 * i + std::size_t(d)] += float(thermalVariance);
      }
    }
  }
};

/// The particles' stays as the residence_time effect counts the tracers': over a window of `window`
/// seconds, only stays that begin and end within it (compareStays weights each by window / (window -
/// d) to undo that). `members` particles on the area-uniform radii R sqrt((k + 0.5) / members); a
/// particle's stays of duration d number (window - d) / revolution on average, each kind's fractions
/// carried from one radius to the next so the sample holds the exact number to within one stay.
std::vector<double> referenceStays(const SolidBodyRotation& rotation, int members, double window) {
  std::vector<double> stays;
  double expected = 0.0;
  std::int64_t emitted = 0;
  for (int k = 0; k < members; ++k) {
    const double r = rotation.radius * std::sqrt((k + 0.5) / members);
    for (const double d : rotation.staysPerRevolution(r)) {
      expected += std::max(0.0, window - d) / rotation.revolution();
      for (; emitted < std::int64_t(std::floor(expected)); ++emitted) stays.push_back(d);
    }
  }
  return stays;
}

/// 0.2 m x 0.2 m x 0.01 m box of 5 mm cells, dt = dt_rec = 5 ms, the bed mass that of the disk; the zone
/// a band across the whole box (its cone's apex far below, a 1 degree half-angle).
Scene orbitScene(const SolidBodyRotation& rotation, long tracers, std::vector<std::string> effects, double d0) {
  const Vec3 size(0.2, 0.2, 0.01);
  Scene s = boxScene(size, 0.005, tracers, 0.005, std::move(effects),
                     rotation.alpha0 * rotation.diskArea() / (size.x() * size.y()));
  s.rcfd.d0 = d0;
  s.spray.spray_zone.apex = Vec3(0.0, -10.0, 0.005);
  s.spray.spray_zone.half_angle_deg = 1.0;
  s.spray.spray_zone.y_min = rotation.centreY + rotation.bandLow;
  s.spray.spray_zone.y_max = rotation.centreY + rotation.bandHigh;
  return s;
}

std::shared_ptr<FieldDatabase> orbitDatabase(const Scene& s, const SolidBodyRotation& rotation) {
  const CartesianGrid grid = gridOf(s);
  return database(s, 4, s.rcfd.dt, [&](int, double, FieldFrame& f) { rotation.fill(grid, f); });
}

struct Outcome {
  nlohmann::json summary;
  std::vector<std::int64_t> stayCounts;
  TracerCloud cloud;
};

Outcome run(const Scene& s, std::shared_ptr<FieldDatabase> db, std::int64_t steps, std::int64_t discard) {
  omp_set_num_threads(1);  // the test's budget: one core
  const RecurrencePath path = sequentialPath(db->frameCount(), steps + 2);
  auto sim = std::make_unique<TracerSimulation>(s, db, path, TracerRunSettings{11, steps, discard});
  for (std::int64_t k = 0; k < steps; ++k) sim->step();
  Outcome o;
  h5::File out(tempPath("orbit-stays-result.h5"), h5::File::Mode::Create);
  sim->writeResults(out, o.summary);
  if (out.exists("/residence_time/duration_steps_counts")) o.stayCounts = out.readInt64s("/residence_time/duration_steps_counts");
  o.cloud = sim->cloud();
  omp_set_num_threads(2);
  return o;
}

const std::vector<std::string> kMeanModel = {"transport", "fluctuation", "walls", "tracer_volume_fraction",
                                             "residence_time"};
const std::vector<std::string> kLangevinModel = {"transport", "directed_relaxation", "langevin_velocity", "walls",
                                                 "tracer_volume_fraction", "residence_time"};

constexpr long kTracers = 5000;
constexpr int kReferenceMembers = 20000;
// 6.5 s (5.2 revolutions), the first 1.3 s (one revolution) discarded.
constexpr std::int64_t kSteps = 1300, kDiscard = 260;

/// Runs the model on the rotation and checks the stays, the holdup, the walls and the count.
void expectTheParticlesStaysAndHoldup(const std::vector<std::string>& effects, double d0,
                                      const SolidBodyRotation& rotation = {},
                                      const std::string& velocityInterpolation = "trilinear") {
  Scene s = orbitScene(rotation, kTracers, effects, d0);
  s.rcfd.velocity_interpolation = velocityInterpolation;
  const Outcome o = run(s, orbitDatabase(s, rotation), kSteps, kDiscard);
  const double dt = s.rcfd.dt, window = double(kSteps - kDiscard) * dt;

  const auto c = analysis::compareStays(o.stayCounts, dt, double(kTracers), window,
                                        referenceStays(rotation, kReferenceMembers, window), kReferenceMembers, window);
  const std::string report = c.toJson().dump(1);
  EXPECT_LT(std::abs(c.meanError()), 0.10) << report;
  EXPECT_LT(std::abs(c.crossingRateError()), 0.10) << report;
  EXPECT_LE(c.ksDistance, 0.10) << report;

  // The holdup is reported in particles (tracers in the zone times particles per tracer).
  const double particleVolume = kPi / 6.0 * std::pow(s.particles.diameter, 3);
  const double exactHoldup = rotation.alpha0 * rotation.bandAreaInDisk() * s.apparatus.size.z() / particleVolume;
  const double holdup = o.summary["holdup"]["mean"].get<double>();
  EXPECT_NEAR(holdup / exactHoldup, 1.0, 0.05) << o.summary["holdup"].dump() << " exact " << exactHoldup;

  if (o.summary.contains("langevin_velocity")) {
    EXPECT_TRUE(o.summary["langevin_velocity"]["active"].get<bool>());
  }

  ASSERT_EQ(o.cloud.size(), std::size_t(kTracers));
  const Apparatus box(s.apparatus);
  for (std::size_t i = 0; i < o.cloud.size(); ++i) ASSERT_GE(box.signedDistance(o.cloud.position(i)), -1e-9) << i;
}

}  // namespace

TEST(OrbitStays, TheExactStaysFillTheBandAsItsShareOfTheDisk) {
  // Little's law on the reference: the time a particle spends in the band per revolution, averaged
  // over the disk's area, is the band's share of the disk, the exact holdup fraction.
  const SolidBodyRotation rotation;
  const int members = 200000;
  double timeInBand = 0.0;
  for (int k = 0; k < members; ++k) {
    for (const double d : rotation.staysPerRevolution(rotation.radius * std::sqrt((k + 0.5) / members))) timeInBand += d;
  }
  EXPECT_NEAR(timeInBand / members / rotation.revolution(), rotation.bandAreaInDisk() / rotation.diskArea(), 1e-5);
  // The reference over a window holds (window - d) / revolution stays of duration d per particle.
  const double window = 5.2;
  const auto stays = referenceStays(rotation, kReferenceMembers, window);
  double expected = 0.0;
  for (int k = 0; k < kReferenceMembers; ++k) {
    for (const double d : rotation.staysPerRevolution(rotation.radius * std::sqrt((k + 0.5) / kReferenceMembers)))
      expected += (window - d) / rotation.revolution();
  }
  EXPECT_NEAR(double(stays.size()), expected, 1.0);
}

TEST(OrbitStays, TheDatabaseHoldsTheDiskAndItsRotation) {
  const SolidBodyRotation rotation;
  const Scene s = orbitScene(rotation, 100, kMeanModel, 0.0);
  const CartesianGrid grid = gridOf(s);
  const auto frame = orbitDatabase(s, rotation)->frame(0);
  double volume = 0.0, worstVelocity = 0.0;
  for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
    const std::size_t i = std::size_t(c);
    volume += double(frame->alpha_p[i]) * grid.cellVolume();
    if (frame->alpha_p[i] <= 0.0f) continue;  // the reader's completion, not the rotation
    const auto ijk = grid.cellIjk(c);
    const Eigen::Vector3d p = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
    const Eigen::Vector3d u(-rotation.omega * (p.y() - rotation.centreY), rotation.omega * (p.x() - rotation.centreX), 0.0);
    for (int d = 0; d < 3; ++d) worstVelocity = std::max(worstVelocity, std::abs(double(frame->u_p[3 * i + std::size_t(d)]) - u[d]));
  }
  EXPECT_NEAR(volume / (rotation.alpha0 * rotation.diskArea() * s.apparatus.size.z()), 1.0, 2e-3);
  EXPECT_LT(worstVelocity, 1e-6);
  // The bed mass is the disk's: the tracers stand for its particles.
  EXPECT_NEAR(s.process.bed_mass / s.particles.density, rotation.alpha0 * rotation.diskArea() * s.apparatus.size.z(),
              1e-12);
}

TEST(OrbitStays, MeanModelWithoutRelaxationCrossesTheBandAsTheParticles) {
  expectTheParticlesStaysAndHoldup(kMeanModel, 0.0);
}

TEST(OrbitStays, MeanModelAtASmallD0CrossesTheBandAsTheParticles) {
  expectTheParticlesStaysAndHoldup(kMeanModel, 1e-5);
}

// The mass-weighted velocity is the trilinear one inside the disk (alpha_P uniform there); at its rim it
// leans to the disk's side, which must not pull tracers in or out.
TEST(OrbitStays, MeanModelWithTheMassWeightedVelocityCrossesTheBandAsTheParticles) {
  expectTheParticlesStaysAndHoldup(kMeanModel, 1e-5, {}, "mass_weighted");
}

TEST(OrbitStays, LangevinModelCrossesTheBandAsTheParticles) {
  expectTheParticlesStaysAndHoldup(kLangevinModel, 1e-4);
}

TEST(OrbitStays, LangevinModelWithTheCellsVelocitySpreadCrossesTheBandAsTheParticles) {
  SolidBodyRotation rotation;
  rotation.cellSpread = true;
  expectTheParticlesStaysAndHoldup(kLangevinModel, 1e-4, rotation);
}

TEST(OrbitStays, TheComparisonRejectsAReferenceOfAnotherRotationOrBand) {
  // The bounds above can fail: the tracers of the rotation against the stays and holdup of a rotation
  // 20 % faster, and of a band two cells higher.
  const SolidBodyRotation rotation;
  Scene s = orbitScene(rotation, kTracers, kMeanModel, 0.0);
  const Outcome o = run(s, orbitDatabase(s, rotation), kSteps, kDiscard);
  const double dt = s.rcfd.dt, window = double(kSteps - kDiscard) * dt;

  SolidBodyRotation faster = rotation;
  faster.omega *= 1.2;
  const auto c = analysis::compareStays(o.stayCounts, dt, double(kTracers), window,
                                        referenceStays(faster, kReferenceMembers, window), kReferenceMembers, window);
  EXPECT_GT(std::abs(c.meanError()), 0.10) << c.toJson().dump(1);
  EXPECT_GT(std::abs(c.crossingRateError()), 0.10) << c.toJson().dump(1);
  EXPECT_GT(c.ksDistance, 0.10) << c.toJson().dump(1);

  SolidBodyRotation higher = rotation;
  higher.bandLow += 0.01, higher.bandHigh += 0.01;
  const double particleVolume = kPi / 6.0 * std::pow(s.particles.diameter, 3);
  const double wrongHoldup = higher.alpha0 * higher.bandAreaInDisk() * s.apparatus.size.z() / particleVolume;
  EXPECT_GT(std::abs(o.summary["holdup"]["mean"].get<double>() / wrongHoldup - 1.0), 0.05);
}

// A disk whose particles fluctuate at 0.1 m/s about the rotation and stay in it (a granular temperature
// confined to the bed): the well-mixed drift keeps the tracers distributed as alpha_P^rec, so the band
// holds its share of them and the cells holding particles all of them (the rim's cells reach a cell
// diagonal, 7.1 mm, beyond the disk). Without the fluctuation's reflection where the frame holds no
// particle, 42 % of the tracers drifted out of the disk and the band held 19 % too few.
TEST(OrbitStays, LangevinTracersOfAHotDiskStayInTheDisk) {
  SolidBodyRotation rotation;
  rotation.thermalVariance = 0.01;
  Scene s = orbitScene(rotation, kTracers, kLangevinModel, 1e-4);
  const Outcome o = run(s, orbitDatabase(s, rotation), kSteps, kDiscard);
  const double particleVolume = kPi / 6.0 * std::pow(s.particles.diameter, 3);
  const double exactHoldup = rotation.alpha0 * rotation.bandAreaInDisk() * s.apparatus.size.z() / particleVolume;
  const double holdup = o.summary["holdup"]["mean"].get<double>();
  EXPECT_NEAR(holdup / exactHoldup, 1.0, 0.05) << o.summary["holdup"].dump() << " exact " << exactHoldup;
  int outside = 0;
  for (std::size_t i = 0; i < o.cloud.size(); ++i) {
    const double dx = o.cloud.x[i] - rotation.centreX, dy = o.cloud.y[i] - rotation.centreY;
    outside += std::hypot(dx, dy) > rotation.radius + 0.005 * std::sqrt(2.0);
  }
  EXPECT_LT(outside, int(0.01 * kTracers)) << outside << " of " << kTracers << " beyond the rim";
}

