// DEM walls built from the real rcfd::Apparatus (geometry module): the primitives agree with its
// signed distance, and 20 m/s impacts at the plates' edges and the V's corners never cross a wall
// by the apparatus's own (independent) signed distance.
#include <gtest/gtest.h>

#include <random>

#include "DemTestUtil.hpp"
#include "cfddem/ApparatusWalls.hpp"
#include "geometry/Apparatus.hpp"

namespace rcfd {
namespace {

using Eigen::Vector3d;
using namespace demtest;

const QuietLog quiet;

ApparatusSpec procellWithPlates() {
  ApparatusSpec spec;
  DraftPlatesSpec plates;
  plates.elevation = 0.03;  // clear of the V walls: all four plate edges are exposed
  spec.draft_plates = plates;
  return spec;
}

TEST(ApparatusAdaptor, PrimitivesMatchTheSignedDistance) {
  const Apparatus app(procellWithPlates());
  const DemWalls walls = wallsFromApparatus(app);
  EXPECT_EQ(walls.faces().size(), 6u + 8u + 2u);
  EXPECT_EQ(walls.edges().size(), 8u);
  for (const auto& f : walls.faces()) {
    if (!std::isfinite(f.a_max)) continue;
    const Vector3d mid = f.origin + 0.5 * f.a_max * f.u + 0.1 * f.w;
    EXPECT_NEAR(app.signedDistance(mid), 0.0, 1e-9) << "face mid-point on the boundary";
    EXPECT_NEAR(app.signedDistance(mid + 1e-4 * f.normal), 1e-4, 1e-9) << "normal into the open region";
  }
  for (const auto& e : walls.edges()) EXPECT_NEAR(app.signedDistance(e.origin + 0.1 * e.dir), 0.0, 1e-9);
}

TEST(ApparatusAdaptor, ImpactsAt20MetresPerSecondStayInside) {
  const Apparatus app(procellWithPlates());
  const DemWalls walls = wallsFromApparatus(app);
  const double r = 2.7e-3;  // cg = 3 parcel
  const DemMaterial m = material(r, 0.9, 0.75, 0.5, 0.24, 0.06, 0.05, 5e6, 1040.0);
  std::vector<Vector3d> targets;
  for (const auto& e : walls.edges()) targets.push_back(e.origin + 0.1 * e.dir);  // plate edges
  const auto& spec = app.spec();
  const double wi = 0.5 * spec.inlet_width;
  targets.push_back(Vector3d(wi, 0.0, 0.1));                  // inlet / V wall corner
  targets.push_back(Vector3d(-wi, 0.0, 0.0));                 // triple corner
  DemSettings s;
  s.time_step = 0.25 * m.rayleighTime();
  s.max_overlap_fraction = 1.0;
  std::mt19937_64 rng(17);
  std::normal_distribution<double> g;
  int shots = 0;
  for (const Vector3d& t : targets) {
    int at_target = 0;
    for (int k = 0; k < 2000 && at_target < 6; ++k) {
      Vector3d dir(g(rng), g(rng), g(rng));
      dir.normalize();
      const Vector3d start = t + 4.0 * r * dir;
      if (app.signedDistance(start) < 1.05 * r) continue;
      DemSystem dem(m, walls, s);
      dem.addParticle(start, -20.0 * dir);
      ++at_target;
      for (long k2 = 0; k2 < static_cast<long>(2e-3 / s.time_step); ++k2) {
        dem.step();
        ASSERT_GT(app.signedDistance(dem.particles().x[0]), 0.0) << "through a wall near " << t.transpose();
      }
    }
    EXPECT_EQ(at_target, 6) << t.transpose();
    shots += at_target;
  }
  EXPECT_EQ(shots, 6 * static_cast<int>(targets.size()));
}

}  // namespace
}  // namespace rcfd
