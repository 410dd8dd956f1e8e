// How far the spray zone's particles move between two frames (analysis/FrameSpacing.hpp).
#include <gtest/gtest.h>

#include "../tracers/TracerTestSupport.hpp"
#include "analysis/FrameSpacing.hpp"

namespace rcfd {
namespace {

/// A box of 1 cm cells whose zone is a cone over its middle; particles rise at `speed` in the zone's
/// lower half and at 3 x `speed` in its wider upper half, which holds a quarter of the zone's
/// particle volume: the median is `speed` and the 90th percentile 3 x `speed`. Frames `dtRec` apart.
FrameSpacing spacing(double speed, double dtRec) {
  Scene s = test::boxScene({0.1, 0.1, 0.1}, 0.01, 10, dtRec, {"transport"});
  const CartesianGrid grid = test::gridOf(s);
  const Eigen::Vector3d lo = grid.origin, hi = grid.upperCorner();
  SprayZoneSpec zone;
  zone.apex = Eigen::Vector3d(0.5 * (lo.x() + hi.x()), lo.y(), 0.5 * (lo.z() + hi.z()));
  zone.half_angle_deg = 30.0;
  zone.y_min = lo.y() + 0.02;
  zone.y_max = lo.y() + 0.08;
  const double middle = lo.y() + 0.05;
  const SprayZone cone(zone);
  double cellsBelow = 0.0, cellsAbove = 0.0;  // the zone's cells below and above the middle
  for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
    const auto ijk = grid.cellIjk(c);
    const Eigen::Vector3d x = grid.cellCenter(ijk[0], ijk[1], ijk[2]);
    if (cone.contains(x)) (x.y() > middle ? cellsAbove : cellsBelow) += 1.0;
  }
  const float alphaUpper = float(0.3 * cellsBelow / cellsAbove / 3.0);
  auto db = test::database(s, 6, dtRec, [&](int, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < grid.cellCount(); ++c) {
      const auto ijk = grid.cellIjk(c);
      const bool upper = grid.cellCenter(ijk[0], ijk[1], ijk[2]).y() > middle;
      f.alpha_p[std::size_t(c)] = upper ? alphaUpper : 0.3f;
      f.u_p[3 * std::size_t(c) + 1] = float(upper ? 3.0 * speed : speed);
    }
  });
  return frameSpacing(*db, cone);
}

TEST(FrameSpacing, CellsPerFrameIsTheMedianSpeedTimesTheIntervalOverTheCell) {
  const FrameSpacing dense = spacing(1.0, 0.005);
  EXPECT_GT(dense.zoneCells, 10);
  EXPECT_EQ(dense.framesSampled, 6);
  EXPECT_NEAR(dense.medianSpeed, 1.0, 1e-6);  // the lower half holds more particle volume
  EXPECT_NEAR(dense.p90Speed, 3.0, 1e-6);
  EXPECT_NEAR(dense.cellsPerFrame, 0.5, 1e-6);
  EXPECT_FALSE(dense.sparse());
  EXPECT_TRUE(sparseFramesWarning(dense).empty());
  const FrameSpacing sparse = spacing(1.0, 0.05);
  EXPECT_NEAR(sparse.cellsPerFrame, 5.0, 1e-5);
  EXPECT_TRUE(sparse.sparse());
  const std::string warning = sparseFramesWarning(sparse);
  EXPECT_NE(warning.find("5.0 cells"), std::string::npos) << warning;
  EXPECT_NE(warning.find("0.02 s"), std::string::npos) << warning;  // 2 cells per frame
  EXPECT_EQ(toJson(sparse)["sparse"], true);
}

}  // namespace
}  // namespace rcfd
