// firstIntersection(): known crossings, and a property test over 1e6 random segments (half of them
// built to graze corners, plate tips and edges, to start on the boundary or to run along walls),
// checked against an independent exact segment-in-region test; and reflect-until-done walks.

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <random>

#include "GeometryFixtures.hpp"
#include "geometry/Apparatus.hpp"
#include "../SanitizedBuild.hpp"

namespace rcfd {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr double kInsideTol = 1e-12;  ///< "inside or on": signedDistance >= -kInsideTol

/// Independent exact test (not using Apparatus's own code paths): does the closed segment a-b stay in
/// the closed open region, up to kInsideTol? The outline is convex (both ends inside every edge's
/// half-plane suffices), the depth is a slab, and each plate's interior shrunk by kInsideTol must not
/// be touched (Liang-Barsky overlap of the segment with the open rectangle).
bool segmentInside(const Apparatus& app, const Vector3d& a, const Vector3d& b) {
  const auto& ol = app.outline();
  for (std::size_t i = 0; i < ol.size(); ++i) {
    const Vector2d e = ol[(i + 1) % ol.size()] - ol[i];
    const Vector2d n = Vector2d(-e.y(), e.x()).normalized();
    if (n.dot(a.head<2>() - ol[i]) < -kInsideTol || n.dot(b.head<2>() - ol[i]) < -kInsideTol) return false;
  }
  const double depth = app.depth();
  if (a.z() < -kInsideTol || b.z() < -kInsideTol || a.z() > depth + kInsideTol || b.z() > depth + kInsideTol)
    return false;
  for (const auto& hole : app.holes()) {
    Vector2d lo = hole[0], hi = hole[0];
    for (const auto& p : hole) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    lo.array() += kInsideTol;
    hi.array() -= kInsideTol;
    double t0 = 0.0, t1 = 1.0;
    bool overlaps = true;
    for (int ax = 0; ax < 2 && overlaps; ++ax) {
      const double d = b[ax] - a[ax];
      if (d == 0.0) {
        overlaps = a[ax] > lo[ax] && a[ax] < hi[ax];
        continue;
      }
      double s0 = (lo[ax] - a[ax]) / d, s1 = (hi[ax] - a[ax]) / d;
      if (s0 > s1) std::swap(s0, s1);
      t0 = std::max(t0, s0);
      t1 = std::min(t1, s1);
      overlaps = t0 < t1;
    }
    if (overlaps) return false;
  }
  return true;
}

/// Random segments: half uniform, half built to be hard (see the file comment).
class SegmentFactory {
 public:
  explicit SegmentFactory(const Apparatus& app) : app_(app) {
    for (const auto& p : app.outline()) corners_.push_back(p);
    for (const auto& h : app.holes())
      for (const auto& p : h) corners_.push_back(p);
  }

  Vector3d insidePoint(std::mt19937_64& rng) const {
    const Vector3d lo = app_.lowerCorner(), hi = app_.upperCorner();
    for (;;) {
      const Vector3d p(lo.x() + u(rng) * (hi.x() - lo.x()), lo.y() + u(rng) * (hi.y() - lo.y()),
                       lo.z() + u(rng) * (hi.z() - lo.z()));
      if (app_.contains(p)) return p;
    }
  }
  Vector3d direction(std::mt19937_64& rng) const {
    std::normal_distribution<double> g;
    return Vector3d(g(rng), g(rng), g(rng)).normalized();
  }
  double length(std::mt19937_64& rng) const { return std::pow(10.0, -7.0 + 7.0 * u(rng)); }
  double tinyOffset(std::mt19937_64& rng) const {
    static constexpr std::array<double, 9> offsets{0.0, 1e-16, 1e-15, 1e-12, 1e-10, 5e-10, 1e-9, 3e-9, 1e-6};
    return offsets[std::size_t(rng() % offsets.size())];
  }
  /// A point on the boundary, with the unit inward normal and a unit direction along the face.
  void boundaryPoint(std::mt19937_64& rng, Vector3d& p, Vector3d& n, Vector3d& along) const {
    const auto& edges = app_.sectionEdges();
    const std::size_t pick = rng() % (edges.size() + 2);
    const double z = (rng() % 8 == 0) ? (rng() % 2) * app_.depth() : u(rng) * app_.depth();
    if (pick < edges.size()) {
      const auto& e = edges[pick];
      // Endpoints now and then, so we also start exactly at corners.
      const double t = rng() % 6 == 0 ? double(rng() % 2) : u(rng);
      const Vector2d q = e.a + t * (e.b - e.a);
      const Vector2d dir = (e.b - e.a).normalized();
      p = Vector3d(q.x(), q.y(), z);
      n = Vector3d(-dir.y(), dir.x(), 0.0);
      along = (rng() % 3 == 0) ? Vector3d(0, 0, 1) : Vector3d(dir.x(), dir.y(), 0.0);
    } else {
      const bool low = pick == edges.size();
      p = insidePoint(rng);
      p.z() = low ? 0.0 : app_.depth();
      n = Vector3d(0, 0, low ? 1.0 : -1.0);
      along = Vector3d(u(rng) - 0.5, u(rng) - 0.5, 0.0).normalized();
    }
  }

  void make(std::uint64_t index, std::mt19937_64& rng, Vector3d& a, Vector3d& b) const {
    const int kind = int(index % 10);
    if (kind < 5) {  // uniform: inside start, random direction and length over 7 decades
      a = insidePoint(rng);
      b = a + length(rng) * direction(rng);
      return;
    }
    if (kind == 5 || kind == 8) {  // through (or within a hair of) a corner or plate tip
      const Vector2d c = corners_[rng() % corners_.size()];
      const double z = rng() % 4 == 0 ? (rng() % 2) * app_.depth() : u(rng) * app_.depth();
      const Vector3d corner(c.x(), c.y(), z);
      a = insidePoint(rng);
      Vector3d through = corner;
      if (kind == 8) through += tinyOffset(rng) * (rng() % 2 ? 1.0 : -1.0) * direction(rng);
      b = through + u(rng) * (through - a);
      if (rng() % 4 == 0) b = through;  // end exactly at the corner
      return;
    }
    Vector3d n, along;
    boundaryPoint(rng, a, n, along);
    if (kind == 6) {  // start on the boundary, any direction
      b = a + length(rng) * direction(rng);
    } else if (kind == 7) {  // parallel to the wall at a tiny offset, both ways, past its end
      a += tinyOffset(rng) * n;
      b = a + (rng() % 2 ? 1.0 : -1.0) * 0.2 * u(rng) * along;
    } else {  // kind 9: start on the boundary, almost along it, slightly in or out
      b = a + 0.1 * u(rng) * (along + (u(rng) - 0.5) * 1e-6 * n);
    }
  }

 private:
  static double u(std::mt19937_64& rng) { return std::uniform_real_distribution<double>(0.0, 1.0)(rng); }
  const Apparatus& app_;
  std::vector<Vector2d> corners_;
};

TEST(ApparatusIntersection, KnownCrossings) {
  const Apparatus app(test::procellSpec(true));
  const double tol = app.boundaryTolerance();
  EXPECT_GT(tol, 0.0);
  EXPECT_LT(tol, 1e-8);
  auto hit = app.firstIntersection({0, 0.3, 0.1}, {0.2, 0.3, 0.1});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->point.x(), 0.125 - tol, 1e-15);
  EXPECT_NEAR(hit->t, (0.125 - tol) / 0.2, 1e-14);
  EXPECT_EQ(hit->normal, Vector3d(-1, 0, 0));
  EXPECT_EQ(hit->kind, BoundaryKind::Wall);
  hit = app.firstIntersection({0, 0.03, 0.1}, {0, -0.05, 0.1});
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->kind, BoundaryKind::Inlet);
  EXPECT_NEAR(hit->point.y(), tol, 1e-15);
  EXPECT_EQ(hit->normal, Vector3d(0, 1, 0));
  hit = app.firstIntersection({0.1, 0.5, 0.1}, {0.1, 0.7, 0.1});
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->kind, BoundaryKind::Outlet);
  hit = app.firstIntersection({0, 0.06, 0.1}, {0.05, 0.06, 0.1});
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->kind, BoundaryKind::Plate);
  EXPECT_NEAR(hit->point.x(), 0.0225 - tol, 1e-15);
  EXPECT_EQ(hit->normal, Vector3d(-1, 0, 0));
  hit = app.firstIntersection({0, 0.3, 0.1}, {0, 0.3, 0.3});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 0.5 - tol / 0.2, 1e-14);
  EXPECT_EQ(hit->normal, Vector3d(0, 0, -1));
  // Onto the top of a plate from above, and into the V wall.
  hit = app.firstIntersection({0.0235, 0.12, 0.1}, {0.0235, 0.08, 0.1});
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->normal, Vector3d(0, 1, 0));
  EXPECT_NEAR(hit->point.y(), 0.095 + tol, 1e-15);
  hit = app.firstIntersection({0.05, 0.1, 0.1}, {0.09, 0.02, 0.1});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->normal.x(), -std::sqrt(3.0) / 2, 1e-15);
  EXPECT_NEAR(app.signedDistance(hit->point), tol, 1e-15);
  // No crossing: inside, passing between the plates, zero length, along the inlet.
  EXPECT_FALSE(app.firstIntersection({0, 0.02, 0.1}, {0, 0.3, 0.15}));
  EXPECT_FALSE(app.firstIntersection({0, 0.3, 0.1}, {0, 0.3, 0.1}));
  EXPECT_FALSE(app.firstIntersection({-0.009, 0.0, 0.1}, {0.009, 0.0, 0.1}));
  // ... but ending exactly at the inlet corner is ending on the V wall: a hit just before it.
  hit = app.firstIntersection({-0.01, 0.0, 0.1}, {0.01, 0.0, 0.1});
  ASSERT_TRUE(hit);
  EXPECT_GT(hit->t, 1.0 - 1e-6);
  // Starting on a wall: moving out hits at t = 0, moving in does not.
  hit = app.firstIntersection({0.125, 0.3, 0.1}, {0.13, 0.3, 0.1});
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->t, 0.0);
  EXPECT_EQ(hit->point, Vector3d(0.125, 0.3, 0.1));
  EXPECT_FALSE(app.firstIntersection({0.125, 0.3, 0.1}, {0.12, 0.3, 0.1}));
  // Grazing the plate tip exactly: the corner counts as part of the plate.
  hit = app.firstIntersection({0.0, 0.095 - 0.0225, 0.1}, {0.045, 0.095 + 0.0225, 0.1});
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->kind, BoundaryKind::Plate);
}

TEST(ApparatusIntersection, MillionRandomSegmentsNeverCrossAWall) {
  constexpr std::int64_t kSegments = 1'000'000;
  // 1e6 segments with the plates, 2.5e5 without, 1e5 in a pseudo-2D box (a thin verification slice).
  for (int variant : {0, 1, 2}) {
    const Apparatus app(variant == 2 ? test::boxSpec(0.1, 0.3, 0.004, true) : test::procellSpec(variant == 0));
    const bool withPlates = variant == 0;
    const SegmentFactory factory(app);
    const double tol = app.boundaryTolerance();
    const std::int64_t n = withPlates ? kSegments : variant == 1 ? kSegments / 4 : kSegments / 10;
    std::int64_t badHitPoint = 0, farHit = 0, badNormal = 0, crossedBeforeHit = 0, badEnd = 0,
                 leftWithoutHit = 0, sampledOut = 0, hits = 0, startHits = 0;
#pragma omp parallel for schedule(static, 4096) reduction(+ : badHitPoint, farHit, badNormal, \
    crossedBeforeHit, badEnd, leftWithoutHit, sampledOut, hits, startHits)
    for (std::int64_t i = 0; i < n; ++i) {
      std::mt19937_64 rng(std::uint64_t(i) * 0x9E3779B97F4A7C15ull + std::uint64_t(variant));
      Vector3d a, b;
      factory.make(std::uint64_t(i), rng, a, b);
      const auto hit = app.firstIntersection(a, b);
      Vector3d end = b;
      if (hit) {
        ++hits;
        startHits += hit->t == 0.0;
        const double sd = app.signedDistance(hit->point);
        badHitPoint += sd < -kInsideTol;
        farHit += sd > 3.0 * tol;  // a reported hit lies at a boundary, not in the middle of nowhere
        badNormal += std::abs(hit->normal.norm() - 1.0) > 1e-12 || hit->normal.dot(b - a) >= 0.0 ||
                     hit->t < 0.0 || hit->t > 1.0;
        crossedBeforeHit += !segmentInside(app, a, hit->point);
        end = hit->point;
      } else {
        badEnd += app.signedDistance(b) < -kInsideTol;
        leftWithoutHit += !segmentInside(app, a, b);
      }
      if (i % 97 == 0) {  // dense sampling of the travelled part for a subset
        for (int s = 0; s <= 64; ++s) sampledOut += app.signedDistance(a + (s / 64.0) * (end - a)) < -kInsideTol;
      }
    }
    SCOPED_TRACE(variant == 0 ? "with draft plates" : variant == 1 ? "unstabilised" : "thin box");
    EXPECT_EQ(badHitPoint, 0);
    EXPECT_EQ(farHit, 0);
    EXPECT_EQ(badNormal, 0);
    EXPECT_EQ(crossedBeforeHit, 0);
    EXPECT_EQ(badEnd, 0);
    EXPECT_EQ(leftWithoutHit, 0);
    EXPECT_EQ(sampledOut, 0);
    // The generator does exercise both outcomes and starts on the boundary.
    EXPECT_GT(hits, n / 10);
    EXPECT_LT(hits, n);
    EXPECT_GT(startHits, n / 100);
  }
}

TEST(ApparatusIntersection, ReflectUntilDoneNeverEndsOutside) {
  constexpr int kWalks = 100'000, kMaxBounces = 1000;
  for (bool withPlates : {true, false}) {
    const Apparatus app(test::procellSpec(withPlates));
    const SegmentFactory factory(app);
    std::int64_t outside = 0, capped = 0, bounces = 0;
#pragma omp parallel for schedule(static, 1024) reduction(+ : outside, capped, bounces)
    for (int w = 0; w < kWalks; ++w) {
      std::mt19937_64 rng(std::uint64_t(w) + 12345);
      Vector3d a, b;
      factory.make(std::uint64_t(w), rng, a, b);
      if (w % 2 == 0) b = a + 2.0 * factory.direction(rng);  // long flights: many bounces
      int k = 0;
      while (auto hit = app.firstIntersection(a, b)) {
        if (++k > kMaxBounces) break;
        const Vector3d rest = b - hit->point;
        a = hit->point;
        b = a + rest - 2.0 * rest.dot(hit->normal) * hit->normal;
        outside += app.signedDistance(a) < -kInsideTol;
      }
      capped += k > kMaxBounces;
      bounces += k;
      if (k <= kMaxBounces) outside += app.signedDistance(b) < -kInsideTol;
    }
    EXPECT_EQ(outside, 0);
    EXPECT_EQ(capped, 0);
    EXPECT_GT(bounces, kWalks);  // the long flights did bounce
  }
}

TEST(ApparatusIntersection, MoveWithMirrorReflection) {
  const Apparatus app(test::procellSpec(true));
  // Straight into the right wall 0.025 m beyond it: mirrored back to x = 0.125 - 0.025 (to tol).
  auto m = moveWithMirrorReflection(app, {0.1, 0.3, 0.1}, {0.15, 0.3, 0.1});
  EXPECT_EQ(m.bounces, 1);
  EXPECT_FALSE(m.capped);
  EXPECT_NEAR(m.end.x(), 0.1, 1e-8);
  EXPECT_NEAR(m.end.y(), 0.3, 0.0);
  // Into the corner of the side wall and z = 0 at 45 deg: two bounces, both components mirrored.
  m = moveWithMirrorReflection(app, {0.12, 0.3, 0.005}, {0.13, 0.3, -0.005});
  EXPECT_EQ(m.bounces, 2);
  EXPECT_NEAR(m.end.x(), 0.12, 1e-8);
  EXPECT_NEAR(m.end.z(), 0.005, 1e-8);
  // A long flight bounces many times and ends inside; capped at 1 it stops at the next hit point.
  m = moveWithMirrorReflection(app, {0.0, 0.3, 0.1}, {3.0, 0.9, 2.1});
  EXPECT_GT(m.bounces, 10);
  EXPECT_GE(app.signedDistance(m.end), 0.0);
  m = moveWithMirrorReflection(app, {0.0, 0.3, 0.1}, {3.0, 0.9, 2.1}, 1);
  EXPECT_TRUE(m.capped);
  EXPECT_EQ(m.bounces, 1);
  EXPECT_GE(app.signedDistance(m.end), 0.0);
  EXPECT_LT(app.signedDistance(m.end), 1e-8);
}

TEST(ApparatusIntersection, Throughput) {
  // Not a benchmark (bench/ has those) but a guard: the tracer engine calls this per tracer per step.
  const Apparatus app(test::procellSpec(true));
  const SegmentFactory factory(app);
  std::mt19937_64 rng(3);
  std::vector<std::array<Vector3d, 2>> segs(200'000);
  for (auto& s : segs) {
    s[0] = factory.insidePoint(rng);
    s[1] = s[0] + 0.005 * factory.direction(rng);  // a tracer step: ~1 m/s times 5 ms
  }
  const auto t0 = std::chrono::steady_clock::now();
  std::int64_t hits = 0;
  for (int rep = 0; rep < 5; ++rep)
    for (const auto& s : segs) hits += bool(app.firstIntersection(s[0], s[1]));
  const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double rate = 5.0 * segs.size() / dt;
  std::printf("firstIntersection: %.1f M segments/s on one thread (%lld hits)\n", rate / 1e6,
              static_cast<long long>(hits));
  const auto t1 = std::chrono::steady_clock::now();
  double sum = 0.0;
  for (int rep = 0; rep < 5; ++rep)
    for (const auto& s : segs) sum += app.signedDistance(s[1]);
  const double dt2 = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  std::printf("signedDistance:    %.1f M points/s on one thread (checksum %.3f)\n",
              5.0 * segs.size() / dt2 / 1e6, sum);
  if (!test::kSanitizedBuild) {
    EXPECT_GT(rate, 5e5);  // generous: the machine is shared; see docs/geometry.md for measured rates
  }
}

}  // namespace
}  // namespace rcfd
