// Walls: concave corners act with both faces, convex plate edges as edges, and 20 m/s impacts
// against walls, plate edges and corners never let a particle through.
#include <gtest/gtest.h>

#include <random>

#include "DemTestUtil.hpp"
#include "ProCellSection.hpp"
#include "cfddem/ApparatusWalls.hpp"

namespace rcfd {
namespace {

using Eigen::Vector3d;
using namespace demtest;

const QuietLog quiet;
constexpr double kR = 2.7e-3;  // a cg = 3 parcel of the paper's 1.8 mm particles

DemMaterial paperParcel() { return material(kR, 0.9, 0.75, 0.5, 0.24, 0.06, 0.05, 5e6, 1040.0); }

TEST(ApparatusWalls, PrimitivesOfTheProCell) {
  ProCell cell;
  cell.plate.elevation = 0.01;
  const DemWalls walls = wallsFromSection(cell.edges(), cell.spec.depth);
  EXPECT_EQ(walls.faces().size(), 6u + 8u + 2u);  // outline, plate sides, z = 0 and z = depth
  EXPECT_EQ(walls.edges().size(), 8u);            // the plates' long edges; the outline is convex
  int checked = 0;
  cell.plate.elevation = 0.01;  // the scene default: the plates' lower ends inside the V walls
  for (const auto& f : walls.faces()) {
    if (!std::isfinite(f.a_max)) continue;
    // Every normal points into the open region. (With the default plates the plates' lower ends lie
    // inside the V walls; faces there are not on the boundary and are skipped.)
    const Vector3d mid = f.origin + 0.5 * f.a_max * f.u + 0.1 * f.w;
    if (std::abs(cell.clearance(mid)) > 1e-12) continue;
    EXPECT_GT(cell.clearance(mid + 1e-4 * f.normal), 0.0) << f.origin.transpose();
    ++checked;
  }
  EXPECT_EQ(checked, 12);
}

TEST(ApparatusWalls, SphereInTheVFeelsBothWalls) {
  ProCell cell;
  cell.spec.inlet_width = 0.002;  // narrower than the sphere: it rests on the two V walls
  const DemMaterial m = paperParcel();
  DemSettings s;
  s.time_step = 1e-5;
  s.max_overlap_fraction = 1.0;
  s.rolling_model = "cdt";
  DemSystem dem(m, wallsFromSection(cell.edges(), cell.spec.depth), s);
  dem.addParticle(Vector3d(0.001, 0.02, 0.1));
  dem.run(40000);
  const Vector3d c = dem.particles().x[0];
  EXPECT_EQ(dem.lastStats().wall_contacts, 2);
  // centre at distance r from both walls: y = 2 (r - w_i sin 60)
  const double yc = 2.0 * (kR - cell.wi() * std::sin(M_PI / 3));
  EXPECT_NEAR(c.y(), yc, 0.01 * kR);
  EXPECT_NEAR(c.x(), 0.0, 0.01 * kR);
}

TEST(ApparatusWalls, PlateTipActsAsAnEdge) {
  ProCell cell;
  const DemMaterial m = paperParcel();
  DemSettings s;
  s.time_step = 1e-6;
  s.max_overlap_fraction = 1.0;
  s.gravity.setZero();
  DemSystem dem(m, wallsFromSection(cell.edges(), cell.spec.depth), s);
  const auto plate = cell.plateRects()[0];
  // Falls onto the plate's outer top corner, offset outwards by half a radius.
  dem.addParticle(Vector3d(plate[2] + 0.5 * kR, plate[3] + 2 * kR, 0.1), Vector3d(0, -2.0, 0));
  bool edge_contact = false;
  for (int k = 0; k < 3000; ++k) {
    dem.step();
    const auto& walls = dem.walls();
    WallContact wc;
    for (std::size_t e = walls.faces().size(); e < walls.size(); ++e)
      edge_contact |= walls.contact(e, dem.particles().x[0], kR, wc);
    ASSERT_GT(cell.clearance(dem.particles().x[0]), 0.0);
  }
  EXPECT_TRUE(edge_contact);
  EXPECT_GT(dem.particles().v[0].x(), 0.1) << "deflected outwards by the edge";
}

// Shoots single parcels at 20 m/s at faces, concave corners, plate faces and convex plate edges,
// from several directions, with the coarsest time step the Rayleigh rule allows.
TEST(ApparatusWalls, ImpactsAt20MetresPerSecondNeverPassAWall) {
  ProCell cell;
  const DemMaterial m = paperParcel();
  const DemWalls walls = wallsFromSection(cell.edges(), cell.spec.depth);
  const double w = 0.5 * cell.spec.width;
  const auto p = cell.plateRects()[0];
  const double z = 0.1;
  std::vector<Vector3d> targets = {
      {0.0, 0.0, z},                                  // inlet (a wall for particles)
      {cell.wi(), 0.0, z},                            // inlet / V wall corner
      {0.5 * (cell.wi() + w), 0.5 * cell.yv(), z},    // V wall
      {w, cell.yv(), z},                              // V wall / side wall corner
      {w, 0.4, z},                                    // side wall
      {0.0, cell.spec.height, z},                     // outlet (a wall for particles)
      {p[0], 0.5 * (p[1] + p[3]), z},                 // plate inner face
      {p[2], 0.5 * (p[1] + p[3]), z},                 // plate outer face
      {p[0], p[3], z}, {p[2], p[3], z},               // plate top edges (convex)
      {0.5 * (p[0] + p[2]), p[3], z},                 // plate top
      {p[0], p[1], z}, {p[2], p[1], z},               // plate bottom edges (convex)
      {0.5 * (p[0] + p[2]), p[1], z},                 // plate bottom
      {0.1, 0.3, 0.0},                                // z = 0 face
      {w, 0.3, 0.0},                                  // side wall / z face corner
      {cell.wi(), 0.0, 0.0},                          // triple corner at the inlet
  };
  std::mt19937_64 rng(11);
  std::normal_distribution<double> gauss;
  for (double dt : {1e-6, 0.25 * m.rayleighTime()}) {
    DemSettings s;
    s.time_step = dt;
    s.max_overlap_fraction = 1.0;
    int shots = 0;
    double worst = 1.0;
    for (const Vector3d& t : targets) {
      int at_target = 0;
      for (int k = 0; k < 2000 && at_target < 8; ++k) {
        Vector3d dir(gauss(rng), gauss(rng), gauss(rng));
        dir.normalize();
        const Vector3d start = t + 4.0 * kR * dir;
        if (cell.clearance(start) < 1.05 * kR) continue;  // that direction points into a wall
        DemSystem dem(m, walls, s);
        dem.addParticle(start, -20.0 * dir);
        ++shots;
        ++at_target;
        const long steps = static_cast<long>(2e-3 / dt);
        for (long k2 = 0; k2 < steps; ++k2) {
          dem.step();
          const double c = cell.clearance(dem.particles().x[0]);
          worst = std::min(worst, c / kR);
          ASSERT_GT(c, 0.0) << "through a wall near " << t.transpose() << " dt " << dt;
        }
      }
      EXPECT_EQ(at_target, 8) << "too few shots at " << t.transpose();
    }
    EXPECT_EQ(shots, 8 * static_cast<int>(targets.size()));
    RecordProperty("closest_centre_over_radius", std::to_string(worst));
    EXPECT_GT(worst, 0.05) << "the centre came within " << worst << " r of a wall";
  }
}

TEST(BoxWalls, RandomBarrageAt20MetresPerSecondStaysInside) {
  const DemMaterial m = paperParcel();
  DemSettings s;
  s.time_step = 1e-6;
  s.max_overlap_fraction = 1.0;
  const Vector3d lo(-0.02, 0.0, 0.0), hi(0.02, 0.04, 0.04);
  DemSystem dem(m, DemWalls::box(lo, hi), s);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) {
        Vector3d v(g(rng), g(rng), g(rng));
        dem.addParticle(lo + Vector3d(0.005 + 0.01 * i, 0.005 + 0.01 * j, 0.005 + 0.01 * k),
                        20.0 * v.normalized());
      }
  for (int k = 0; k < 5000; ++k) {
    dem.step();
    for (const auto& x : dem.particles().x) {
      ASSERT_TRUE((x.array() > lo.array()).all() && (x.array() < hi.array()).all()) << x.transpose();
    }
  }
  EXPECT_GT(dem.maxOverlapFractionSeen(), 0.1) << "the impacts must be violent";
}

}  // namespace
}  // namespace rcfd
