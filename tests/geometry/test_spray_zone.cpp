// SprayZone: containment at known points, the analytic volume against Monte Carlo, and validation.

#include <gtest/gtest.h>

#include <random>

#include "GeometryFixtures.hpp"
#include "geometry/Apparatus.hpp"
#include "geometry/SprayZone.hpp"

namespace rcfd {
namespace {

using Eigen::Vector3d;

SprayZoneSpec paperZone() {
  SprayZoneSpec z;
  z.apex = Vector3d(0.0, 0.0, 0.1);
  z.half_angle_deg = 17.0;
  z.y_min = 0.02;
  z.y_max = 0.1;
  return z;
}

TEST(SprayZone, Containment) {
  const SprayZone zone(paperZone());
  const double t17 = std::tan(17.0 * std::numbers::pi / 180.0);
  EXPECT_NEAR(zone.radiusAt(0.1), 0.1 * t17, 1e-15);
  EXPECT_EQ(zone.radiusAt(-0.01), 0.0);
  EXPECT_TRUE(zone.contains({0.0, 0.05, 0.1}));
  EXPECT_TRUE(zone.contains({0.0, 0.02, 0.1}));    // on the lower cut
  EXPECT_TRUE(zone.contains({0.0, 0.1, 0.1}));     // on the upper cut
  EXPECT_FALSE(zone.contains({0.0, 0.019, 0.1}));  // below the cut, though inside the cone
  EXPECT_FALSE(zone.contains({0.0, 0.101, 0.1}));
  const double r = 0.05 * t17;
  EXPECT_TRUE(zone.contains({0.999 * r, 0.05, 0.1}));
  EXPECT_FALSE(zone.contains({1.001 * r, 0.05, 0.1}));
  // Rotationally symmetric about the y axis through the apex (x and z alike).
  EXPECT_TRUE(zone.contains({0.0, 0.05, 0.1 + 0.999 * r}));
  EXPECT_FALSE(zone.contains({0.0, 0.05, 0.1 - 1.001 * r}));
  EXPECT_TRUE(zone.contains({0.7 * r, 0.05, 0.1 + 0.7 * r}));
  EXPECT_FALSE(zone.contains({0.72 * r, 0.05, 0.1 + 0.72 * r}));
}

TEST(SprayZone, VolumeMatchesFrustumAndMonteCarlo) {
  const SprayZone zone(paperZone());
  const double t17 = std::tan(17.0 * std::numbers::pi / 180.0);
  const double r0 = 0.02 * t17, r1 = 0.1 * t17, h = 0.08;
  // Frustum formula, independent of the implementation's cone difference.
  EXPECT_NEAR(zone.volume(), std::numbers::pi * h / 3.0 * (r0 * r0 + r0 * r1 + r1 * r1), 1e-18);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  constexpr int kSamples = 2'000'000;
  int in = 0;
  for (int i = 0; i < kSamples; ++i)
    in += zone.contains({r1 * u(rng), 0.06 + 0.04 * u(rng), 0.1 + r1 * u(rng)});
  const double boxVolume = 2 * r1 * 0.08 * 2 * r1;
  const double p = double(in) / kSamples;
  const double sigma = boxVolume * std::sqrt(p * (1 - p) / kSamples);
  EXPECT_NEAR(p * boxVolume, zone.volume(), 4 * sigma);
  // An off-centre apex only moves the zone.
  SprayZoneSpec moved = paperZone();
  moved.apex = Vector3d(0.03, 0.01, 0.05);
  moved.y_min = 0.03;
  moved.y_max = 0.11;
  EXPECT_NEAR(SprayZone(moved).volume(), zone.volume(), 1e-18);
  EXPECT_TRUE(SprayZone(moved).contains({0.03, 0.05, 0.05}));
}

/// Monte Carlo estimate of the zone's volume inside the apparatus, with its standard error.
std::pair<double, double> monteCarloInside(const SprayZone& zone, const Apparatus& app) {
  const auto& z = zone.spec();
  const double r1 = zone.radiusAt(z.y_max);
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  constexpr int kSamples = 2'000'000;
  int in = 0;
  const double yc = 0.5 * (z.y_min + z.y_max), hy = 0.5 * (z.y_max - z.y_min);
  for (int i = 0; i < kSamples; ++i) {
    const Vector3d p(z.apex.x() + r1 * u(rng), yc + hy * u(rng), z.apex.z() + r1 * u(rng));
    in += zone.contains(p) && app.contains(p);
  }
  const double box = 2 * r1 * 2 * hy * 2 * r1, p = double(in) / kSamples;
  return {p * box, box * std::sqrt(p * (1 - p) / kSamples)};
}

TEST(SprayZone, VolumeInsideTheApparatus) {
  // The paper's zone lies wholly inside the unstabilised bed: the clipped volume is the full one.
  const SprayZone zone(paperZone());
  const Apparatus bed(test::procellSpec(false));
  EXPECT_NEAR(zone.volumeInside(bed) / zone.volume(), 1.0, 1e-8);
  // The plates cut into it above y = 0.0736 m; a thin slice (depth 0.02 m) cuts it in z; an apex off
  // the axis pushes it through the V wall. Each against Monte Carlo.
  const Apparatus plates(test::procellSpec(true));
  const double withPlates = zone.volumeInside(plates);
  EXPECT_LT(withPlates, zone.volume());
  auto [mc, sigma] = monteCarloInside(zone, plates);
  EXPECT_NEAR(withPlates, mc, 4 * sigma);

  auto sliceSpec = test::procellSpec(true);
  sliceSpec.depth = 0.02;
  const Apparatus slice(sliceSpec);
  SprayZoneSpec inSlice = paperZone();
  inSlice.apex.z() = 0.01;
  const SprayZone sliceZone(inSlice);
  const double v = sliceZone.volumeInside(slice);
  EXPECT_LT(v, 0.6 * sliceZone.volume());
  std::tie(mc, sigma) = monteCarloInside(sliceZone, slice);
  EXPECT_NEAR(v, mc, 4 * sigma);

  SprayZoneSpec offAxis = paperZone();
  offAxis.apex = Vector3d(0.05, 0.0, 0.1);
  const SprayZone offZone(offAxis);
  const double vo = offZone.volumeInside(bed);
  EXPECT_LT(vo, 0.9 * offZone.volume());
  EXPECT_GT(vo, 0.0);
  std::tie(mc, sigma) = monteCarloInside(offZone, bed);
  EXPECT_NEAR(vo, mc, 4 * sigma);
}

TEST(SprayZone, DraftPlatesShadowTheZoneSeenFromItsApex) {
  // ProCell's plates: inner faces at x = +-22.5 mm, 2 mm thick, 35-95 mm high; the paper's cone (apex at
  // y = 0) reaches them at y = 73.6 mm and is 30.6 mm wide at y_max = 0.1 m.
  SprayZoneSpec spec = paperZone();
  spec.line_of_sight = true;
  const Apparatus plates(test::procellSpec(true));
  const SprayZone seen(spec, plates);
  const SprayZone cone(paperZone(), plates);
  for (const double side : {-1.0, 1.0}) {
    EXPECT_TRUE(seen.contains({side * 0.020, 0.090, 0.1}));   // in the tube
    EXPECT_FALSE(seen.contains({side * 0.026, 0.090, 0.1}));  // behind the plate
    EXPECT_TRUE(cone.contains({side * 0.026, 0.090, 0.1}));
    EXPECT_FALSE(seen.contains({side * 0.026, 0.099, 0.1}));  // above the annulus: the ray meets the plate at 85.7 mm
    EXPECT_TRUE(seen.contains({side * 0.023, 0.099, 0.1}));   // above the plate's top, seen past its edge (96.8 mm)
    EXPECT_FALSE(seen.contains({side * 0.023, 0.097, 0.1}));  // just below that line (94.9 mm)
  }
  // The volume leaves the shadows out, and agrees with the points the zone contains.
  const double v = seen.volumeInside(plates);
  EXPECT_LT(v, cone.volumeInside(plates));
  const auto [mc, sigma] = monteCarloInside(seen, plates);
  EXPECT_NEAR(v, mc, 4 * sigma);
  // Without plates nothing shadows the zone: the same volume, the same points.
  const Apparatus open(test::procellSpec(false));
  const SprayZone seenOpen(spec, open);
  EXPECT_DOUBLE_EQ(seenOpen.volumeInside(open), SprayZone(paperZone()).volumeInside(open));
  EXPECT_TRUE(seenOpen.contains({0.026, 0.090, 0.1}));
}

TEST(SprayZone, RefusesInvalidSpecs) {
  using V = std::vector<std::string>;
  auto z = paperZone();
  z.half_angle_deg = 90.0;
  EXPECT_EQ(test::violationPointers([&] { SprayZone s(z); }), V{"/spray/spray_zone/half_angle_deg"});
  z = paperZone();
  z.y_max = 0.02;
  EXPECT_EQ(test::violationPointers([&] { SprayZone s(z); }), V{"/spray/spray_zone/y_max"});
  z = paperZone();
  z.y_min = -0.01;
  EXPECT_EQ(test::violationPointers([&] { SprayZone s(z); }), V{"/spray/spray_zone/y_min"});
}

}  // namespace
}  // namespace rcfd
