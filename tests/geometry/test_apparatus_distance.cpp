// Signed distance, normals, nearest points and kinds of the apparatus at known points, plus the
// validation of inconsistent dimensions.

#include <gtest/gtest.h>

#include <random>

#include "GeometryFixtures.hpp"
#include "geometry/Apparatus.hpp"

namespace rcfd {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using test::procellSpec;
using test::procellYv;

const double s60 = std::sin(std::numbers::pi / 3.0), c60 = 0.5;
/// Inward normal of the right V wall (rising from (0.01, 0) at 60 deg).
const Vector3d kRightVNormal(-s60, c60, 0.0);

void expectNear(const Vector3d& a, const Vector3d& b, double tol, const char* what) {
  EXPECT_LT((a - b).norm(), tol) << what << ": got " << a.transpose() << ", expected " << b.transpose();
}

/// Checks distance, normal and kind, and that the nearest point is consistent with them.
void expectNearest(const Apparatus& app, const Vector3d& p, double distance, const Vector3d& normal,
                   BoundaryKind kind, bool checkKind = true) {
  const NearestBoundary nb = app.nearestBoundary(p);
  EXPECT_NEAR(nb.distance, distance, 1e-14) << "at " << p.transpose();
  EXPECT_NEAR(app.signedDistance(p), distance, 1e-14) << "at " << p.transpose();
  expectNear(nb.normal, normal, 1e-12, "normal");
  if (checkKind) {
    EXPECT_EQ(int(nb.kind), int(kind)) << "at " << p.transpose();
  }
  // p = point + distance * normal: the normal points from the boundary into the open region.
  expectNear(nb.point + nb.distance * nb.normal, p, 1e-14, "point + distance * normal");
  EXPECT_NEAR(app.signedDistance(nb.point), 0.0, 1e-14) << "nearest point not on the boundary";
  EXPECT_EQ(app.contains(p), distance >= 0.0) << "at " << p.transpose();
}

TEST(ApparatusDistance, ProcellDimensions) {
  const Apparatus app(procellSpec(false));
  EXPECT_NEAR(app.vWallTop(), 0.19918584287042089, 1e-15);
  EXPECT_NEAR(app.vWallTop(), 0.2, 0.001);  // the paper inserts particles "in the freeboard" above 0.2 m
  expectNear(app.lowerCorner(), Vector3d(-0.125, 0, 0), 1e-15, "lower corner");
  expectNear(app.upperCorner(), Vector3d(0.125, 0.6, 0.2), 1e-15, "upper corner");
  // Rectangle minus the two triangles under the V walls.
  const double area = 0.25 * 0.6 - 0.115 * procellYv();
  EXPECT_NEAR(app.sectionArea(), area, 1e-15);
  EXPECT_NEAR(app.openVolume(), area * 0.2, 1e-15);
  const Apparatus plates(procellSpec(true));
  EXPECT_NEAR(plates.sectionArea(), area - 2 * 0.002 * 0.06, 1e-15);
  EXPECT_NEAR(app.floorHeight(0.0), 0.0, 0.0);
  EXPECT_NEAR(app.floorHeight(0.0245), 0.0145 * std::tan(std::numbers::pi / 3), 1e-15);
  EXPECT_NEAR(app.floorHeight(-0.125), app.vWallTop(), 1e-15);
}

TEST(ApparatusDistance, SectionAreaMatchesShoelaceOfTheEdges) {
  // Independent of the closed form: the shoelace sum over all section edges (holes run clockwise).
  for (bool withPlates : {false, true}) {
    const Apparatus app(procellSpec(withPlates));
    double twice = 0.0;
    for (const auto& e : app.sectionEdges()) twice += e.a.x() * e.b.y() - e.a.y() * e.b.x();
    EXPECT_NEAR(0.5 * twice, app.sectionArea(), 1e-15);
  }
}

TEST(ApparatusDistance, WallsInletOutlet) {
  const Apparatus app(procellSpec(false));
  expectNearest(app, {0.0, 0.0, 0.1}, 0.0, {0, 1, 0}, BoundaryKind::Inlet);
  expectNearest(app, {0.0, 0.001, 0.1}, 0.001, {0, 1, 0}, BoundaryKind::Inlet);
  expectNearest(app, {0.0, -0.01, 0.1}, -0.01, {0, 1, 0}, BoundaryKind::Inlet);
  expectNearest(app, {0.12, 0.3, 0.1}, 0.005, {-1, 0, 0}, BoundaryKind::Wall);
  expectNearest(app, {-0.135, 0.3, 0.1}, -0.01, {1, 0, 0}, BoundaryKind::Wall);
  expectNearest(app, {0.0, 0.59, 0.1}, 0.01, {0, -1, 0}, BoundaryKind::Outlet);
  expectNearest(app, {0.0, 0.61, 0.1}, -0.01, {0, -1, 0}, BoundaryKind::Outlet);
  // On, inside and outside the right V wall, 0.1 m up its slope.
  const Vector3d onV(0.01 + 0.1 * c60, 0.1 * s60, 0.1);
  expectNearest(app, onV, 0.0, kRightVNormal, BoundaryKind::Wall);
  expectNearest(app, onV + 0.003 * kRightVNormal, 0.003, kRightVNormal, BoundaryKind::Wall);
  expectNearest(app, onV - 0.003 * kRightVNormal, -0.003, kRightVNormal, BoundaryKind::Wall);
}

TEST(ApparatusDistance, Corners) {
  const Apparatus app(procellSpec(false));
  const double yv = procellYv();
  // V-to-vertical corner (interior angle 150 deg). Outside, in the corner's wedge (between the outward
  // normals at 0 and -30 deg): the corner is the nearest point.
  const Vector3d corner(0.125, yv, 0.1);
  const double a15 = -15.0 * std::numbers::pi / 180.0;
  const Vector3d out(std::cos(a15), std::sin(a15), 0.0);
  expectNearest(app, corner + 0.01 * out, -0.01, -out, BoundaryKind::Wall);
  EXPECT_LT((app.nearestBoundary(corner + 0.01 * out).point - corner).norm(), 1e-15);
  // Inside on the bisector at distance s from the corner: s sin(75 deg) from both walls.
  const Vector3d bis = Vector3d(-c60, 1.0 - s60, 0.0).normalized();
  const double s = 0.01;
  EXPECT_NEAR(app.signedDistance(corner + s * bis), s * std::sin(75.0 * std::numbers::pi / 180.0), 1e-15);
  expectNearest(app, corner, 0.0, app.nearestBoundary(corner).normal, BoundaryKind::Wall);

  // Inlet corner (0.01, 0) (interior angle 120 deg): outside at -60 deg, the corner is nearest; inside
  // on the bisector (120 deg) both walls are s sin(60 deg) away.
  const Vector3d inletCorner(0.01, 0.0, 0.1);
  const Vector3d out60(0.5, -s60, 0.0);
  expectNearest(app, inletCorner + 0.005 * out60, -0.005, -out60, BoundaryKind::Wall, false);
  const BoundaryKind k = app.nearestBoundary(inletCorner + 0.005 * out60).kind;
  EXPECT_TRUE(k == BoundaryKind::Inlet || k == BoundaryKind::Wall);
  EXPECT_NEAR(app.signedDistance(inletCorner + s * Vector3d(-0.5, s60, 0.0)), s * s60, 1e-15);
  // Below the inlet, between its corners' wedges: the inlet itself.
  expectNearest(app, {-0.009, -0.002, 0.05}, -0.002, {0, 1, 0}, BoundaryKind::Inlet);
  // Top corner (90 deg) from outside: hypotenuse.
  expectNearest(app, {0.128, 0.604, 0.1}, -0.005, Vector3d(-0.6, -0.8, 0.0), BoundaryKind::Wall, false);
}

TEST(ApparatusDistance, DepthFaces) {
  const Apparatus app(procellSpec(false));
  expectNearest(app, {0.0, 0.3, 0.09}, 0.09, {0, 0, 1}, BoundaryKind::Wall);
  expectNearest(app, {0.0, 0.3, 0.195}, 0.005, {0, 0, -1}, BoundaryKind::Wall);
  expectNearest(app, {0.12, 0.3, 0.004}, 0.004, {0, 0, 1}, BoundaryKind::Wall);
  expectNearest(app, {0.0, 0.3, -0.01}, -0.01, {0, 0, 1}, BoundaryKind::Wall);
  expectNearest(app, {0.0, 0.3, 0.21}, -0.01, {0, 0, -1}, BoundaryKind::Wall);
  // Outside across an edge of the extrusion (side wall and z = 0): the hypotenuse, toward the edge.
  expectNearest(app, {0.135, 0.3, -0.01}, -std::sqrt(2.0) * 0.01, Vector3d(-1, 0, 1).normalized(),
                BoundaryKind::Wall);
  EXPECT_LT((app.nearestBoundary({0.135, 0.3, -0.01}).point - Vector3d(0.125, 0.3, 0.0)).norm(), 1e-15);
  // Outside below the V wall and beyond z = depth.
  const Vector3d onV(0.01 + 0.1 * c60, 0.1 * s60, 0.2);
  const Vector3d p = onV - 0.003 * kRightVNormal + Vector3d(0, 0, 0.004);
  expectNearest(app, p, -0.005, Vector3d(0.003 * kRightVNormal - Vector3d(0, 0, 0.004)) / 0.005,
                BoundaryKind::Wall);
}

TEST(ApparatusDistance, DraftPlates) {
  const Apparatus app(procellSpec(true));
  // Right plate: x in [0.0225, 0.0245], y in [0.035, 0.095].
  expectNearest(app, {0.02, 0.06, 0.1}, 0.0025, {-1, 0, 0}, BoundaryKind::Plate);
  expectNearest(app, {0.027, 0.06, 0.1}, 0.0025, {1, 0, 0}, BoundaryKind::Plate);
  expectNearest(app, {-0.02, 0.06, 0.1}, 0.0025, {1, 0, 0}, BoundaryKind::Plate);
  expectNearest(app, {0.023, 0.06, 0.1}, -0.0005, {-1, 0, 0}, BoundaryKind::Plate);
  expectNearest(app, {0.0244, 0.06, 0.1}, -0.0001, {1, 0, 0}, BoundaryKind::Plate);
  expectNearest(app, {0.0225, 0.06, 0.1}, 0.0, {-1, 0, 0}, BoundaryKind::Plate);
  // The tip: above the top edge, diagonally off the top corners, inside just under the top.
  expectNearest(app, {0.0235, 0.097, 0.1}, 0.002, {0, 1, 0}, BoundaryKind::Plate);
  expectNearest(app, {0.0245 + 0.003, 0.095 + 0.004, 0.1}, 0.005, {0.6, 0.8, 0}, BoundaryKind::Plate);
  expectNearest(app, {0.0225 - 0.003, 0.095 + 0.004, 0.1}, 0.005, {-0.6, 0.8, 0}, BoundaryKind::Plate);
  expectNearest(app, {0.0235, 0.0948, 0.1}, -0.0002, {0, 1, 0}, BoundaryKind::Plate);
  // The lower edge and its inner corner.
  expectNearest(app, {0.0235, 0.034, 0.1}, 0.001, {0, -1, 0}, BoundaryKind::Plate);
  expectNearest(app, {0.0225 - 0.0009, 0.035 - 0.0012, 0.1}, 0.0015, {-0.6, -0.8, 0}, BoundaryKind::Plate);
  // Near a plate and a depth face: the smaller wins.
  expectNearest(app, {0.02, 0.06, 0.001}, 0.001, {0, 0, 1}, BoundaryKind::Wall);
  // Inside the plate and beyond z = 0: hypotenuse of the plate and slab distances.
  expectNearest(app, {0.023, 0.06, -0.0012}, -0.0013, Vector3d(-0.0005, 0, 0.0012) / 0.0013,
                BoundaryKind::Plate);
}

TEST(ApparatusDistance, NearestPointIsTheClosestBoundaryPoint) {
  // |signedDistance(p)| must not exceed the distance to any boundary point: checked against random
  // points on every face of the extruded boundary. Together with nearestBoundary().point lying on the
  // boundary at exactly that distance (checked below) this pins the distance from both sides.
  for (bool withPlates : {false, true}) {
    const Apparatus app(procellSpec(withPlates));
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Vector3d> boundary;
    for (const auto& e : app.sectionEdges())
      for (int i = 0; i < 400; ++i) {
        const Vector2d q = e.a + u(rng) * (e.b - e.a);
        boundary.emplace_back(q.x(), q.y(), 0.2 * u(rng));
      }
    for (int i = 0; i < 4000; ++i) {
      Vector3d q(-0.125 + 0.25 * u(rng), 0.6 * u(rng), 0.2 * (i % 2));
      if (app.contains(q)) boundary.push_back(q);
    }
    for (int n = 0; n < 300; ++n) {
      const Vector3d p(-0.15 + 0.3 * u(rng), -0.05 + 0.7 * u(rng), -0.05 + 0.3 * u(rng));
      const NearestBoundary nb = app.nearestBoundary(p);
      EXPECT_NEAR((nb.point - p).norm(), std::abs(nb.distance), 1e-14);
      EXPECT_NEAR(app.signedDistance(nb.point), 0.0, 1e-14);
      EXPECT_NEAR(nb.normal.norm(), 1.0, 1e-14);
      for (const auto& q : boundary) ASSERT_LE(std::abs(nb.distance), (q - p).norm() + 1e-14);
      EXPECT_EQ(app.contains(p), nb.distance >= 0.0);
    }
  }
}

TEST(ApparatusDistance, BoxFaces) {
  const Apparatus box(test::boxSpec(0.1, 0.2, 0.3, true));
  EXPECT_DOUBLE_EQ(box.openVolume(), 0.1 * 0.2 * 0.3);
  EXPECT_DOUBLE_EQ(box.vWallTop(), 0.0);
  expectNearest(box, {0.0, 0.19, 0.15}, 0.01, {0, -1, 0}, BoundaryKind::Outlet);
  expectNearest(box, {0.0, 0.01, 0.15}, 0.01, {0, 1, 0}, BoundaryKind::Wall);
  expectNearest(box, {0.045, 0.1, 0.15}, 0.005, {-1, 0, 0}, BoundaryKind::Wall);
  expectNearest(box, {0.0, 0.1, 0.299}, 0.001, {0, 0, -1}, BoundaryKind::Wall);
  const Apparatus closed(test::boxSpec(0.1, 0.2, 0.3, false));
  expectNearest(closed, {0.0, 0.19, 0.15}, 0.01, {0, -1, 0}, BoundaryKind::Wall);
  // Outside a corner of the box: distance to the vertex.
  expectNearest(closed, {0.06, 0.21, 0.31}, -std::sqrt(3.0) * 0.01, Vector3d(-1, -1, -1).normalized(),
                BoundaryKind::Wall, false);
}

TEST(ApparatusValidation, RefusesInconsistentDimensionsNamingTheField) {
  using test::violationPointers;
  using V = std::vector<std::string>;
  auto spec = procellSpec(false);
  spec.inlet_width = 0.25;
  EXPECT_EQ(violationPointers([&] { Apparatus a(spec); }), V{"/apparatus/inlet_width"});
  spec = procellSpec(false);
  spec.height = 0.19;
  EXPECT_EQ(violationPointers([&] { Apparatus a(spec); }), V{"/apparatus/height"});
  spec = procellSpec(false);
  spec.prism_angle_deg = 90.0;
  EXPECT_EQ(violationPointers([&] { Apparatus a(spec); }), V{"/apparatus/prism_angle_deg"});
  spec = procellSpec(false);
  spec.width = -1.0;
  spec.depth = 0.0;
  EXPECT_EQ(violationPointers([&] { Apparatus a(spec); }), (V{"/apparatus/width", "/apparatus/depth"}));
  // The paper's 10 mm above y = 0 cuts the plates into the V (which is 25 mm high beneath them).
  spec = procellSpec(true);
  spec.draft_plates->elevation = 0.01;
  EXPECT_EQ(violationPointers([&] { Apparatus a(spec); }), V{"/apparatus/draft_plates/elevation"});
  try {
    Apparatus a(spec);
  } catch (const InputError& e) {
    EXPECT_NE(e.violations()[0].message.find("0.0251147"), std::string::npos) << e.violations()[0].message;
  }
  spec = procellSpec(true);
  spec.draft_plates->gap = 0.25;
  EXPECT_EQ(violationPointers([&] { Apparatus a(spec); }), V{"/apparatus/draft_plates/gap"});
  spec = procellSpec(true);
  spec.draft_plates->elevation = 0.55;
  EXPECT_EQ(violationPointers([&] { Apparatus a(spec); }), V{"/apparatus/draft_plates/height"});
  spec = procellSpec(true);
  spec.draft_plates->thickness = 0.0;
  EXPECT_EQ(violationPointers([&] { Apparatus a(spec); }), V{"/apparatus/draft_plates/thickness"});
  auto box = test::boxSpec(0.1, 0.0, 0.1, false);
  EXPECT_EQ(violationPointers([&] { Apparatus a(box); }), V{"/apparatus/size/1"});
  // Consistent specs pass.
  EXPECT_TRUE(violationPointers([&] { Apparatus a(procellSpec(true)); }).empty());
}

}  // namespace
}  // namespace rcfd
