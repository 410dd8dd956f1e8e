// EtaEstimate: the remaining time from the rate of the last window of progress reports.
#include <gtest/gtest.h>

#include <algorithm>

#include "jobs/Progress.hpp"

namespace rcfd {
namespace {

TEST(EtaEstimate, SteadyProgressGivesTheRemainingTimeAtThatRate) {
  EtaEstimate eta(60.0);
  eta.restart(0.0, 0.0);
  double left = -1.0;
  for (int t = 1; t <= 50; ++t) left = eta.update(double(t), t / 100.0);  // 1% per second
  EXPECT_NEAR(left, 50.0, 1e-9);
  EtaEstimate fresh;  // without restart(): from nothing done at time 0
  EXPECT_NEAR(fresh.update(10.0, 0.1), 90.0, 1e-9);
}

TEST(EtaEstimate, FollowsASlowdownWithinTheWindowWhereTheAverageSinceTheStartWouldNot) {
  EtaEstimate eta(60.0);
  eta.restart(0.0, 0.0);
  double fraction = 0.0, left = -1.0;
  for (int t = 1; t <= 50; ++t) left = eta.update(double(t), fraction += 0.01);  // 50% in 50 s
  for (int t = 51; t <= 120; ++t) left = eta.update(double(t), fraction += 0.001);  // then 10x slower
  // The last 60 s ran at 0.1% per second: 43% left takes 430 s. The average since the start (57% in
  // 120 s) would say 91 s.
  EXPECT_NEAR(fraction, 0.57, 1e-12);
  EXPECT_NEAR(left, (1.0 - fraction) / 0.001, 1e-6);
  // And back to full speed: within a window the estimate follows again.
  for (int t = 121; t <= 181; ++t) left = eta.update(double(t), fraction = std::min(1.0, fraction + 0.005));
  EXPECT_NEAR(left, (1.0 - fraction) / 0.005, 1e-6);
}

TEST(EtaEstimate, UnknownWithoutProgressInTheWindowAndAfterARestartUntilProgress) {
  EtaEstimate eta(10.0);
  eta.restart(0.0, 0.2);
  EXPECT_EQ(eta.update(0.0, 0.2), -1.0);  // no time passed
  EXPECT_EQ(eta.update(5.0, 0.2), -1.0);  // no progress
  EXPECT_NEAR(eta.update(10.0, 0.3), 70.0, 1e-9);  // 10% in 10 s since the restart at 20%: 70% left
  for (int t = 11; t <= 30; ++t) eta.update(double(t), 0.3);  // stalled for longer than the window
  EXPECT_EQ(eta.update(31.0, 0.3), -1.0);
}

}  // namespace
}  // namespace rcfd
