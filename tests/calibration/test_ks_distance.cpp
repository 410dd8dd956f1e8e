// The two-sample Kolmogorov-Smirnov distance against cases with known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "analysis/KsDistance.hpp"

using namespace rcfd::analysis;

TEST(KsDistance, IdenticalSamplesAreZero) {
  const std::vector<double> a{0.3, 0.1, 0.7, 0.7, 2.5};
  EXPECT_EQ(ksDistance(a, a), 0.0);
}

TEST(KsDistance, DisjointSamplesAreOne) {
  EXPECT_EQ(ksDistance({0.1, 0.2, 0.3}, {1.0, 2.0}), 1.0);
  EXPECT_EQ(ksDistance({5.0, 6.0}, {1.0, 2.0, 3.0}), 1.0);
}

TEST(KsDistance, HandComputedCase) {
  // F_a steps by 1/4 at 1, 2, 3, 4; F_b by 1/5 at 3, 4, 5, 6, 7. |F_a - F_b| after each value:
  // 1: .25, 2: .5, 3: .75 - .2 = .55, 4: 1 - .4 = .6, 5: .4, 6: .2, 7: 0 -> D = 0.6.
  EXPECT_NEAR(ksDistance({1, 2, 3, 4}, {3, 4, 5, 6, 7}), 0.6, 1e-15);
  // Symmetric in its arguments.
  EXPECT_NEAR(ksDistance({3, 4, 5, 6, 7}, {1, 2, 3, 4}), 0.6, 1e-15);
}

TEST(KsDistance, TiesAreComparedAfterBothSamplesStep) {
  // Both samples step at 1 together: comparing before b's step would report a spurious 1/2.
  EXPECT_NEAR(ksDistance({1, 2}, {1, 1, 2, 2}), 0.0, 1e-15);
  EXPECT_NEAR(ksDistance({1, 1, 1, 2}, {1, 2}), 0.25, 1e-15);
}

TEST(KsDistance, HistogramEqualsExpandedSample) {
  // A weighted sample (values with counts, as a residence-time histogram) is the expanded sample.
  const WeightedSample hist{{0.5, 1.0, 1.5}, {3, 0, 2}};
  const WeightedSample expanded = WeightedSample::unweighted({0.5, 0.5, 0.5, 1.5, 1.5});
  const auto other = WeightedSample::unweighted({0.4, 0.9, 1.2, 1.6});
  EXPECT_DOUBLE_EQ(ksDistance(hist, other), ksDistance(expanded, other));
  EXPECT_EQ(ksDistance(hist, expanded), 0.0);
  // Scaling all weights does not change the distribution.
  const WeightedSample scaled{{0.5, 1.0, 1.5}, {30, 0, 20}};
  EXPECT_EQ(ksDistance(hist, scaled), 0.0);
}

TEST(KsDistance, ShiftedUniformSamplesApproachTheShift) {
  // Two large uniform samples on [0, 1) and [0.2, 1.2): D = 0.2 within the grid spacing.
  std::vector<double> a, b;
  for (int i = 0; i < 1000; ++i) {
    a.push_back(i / 1000.0);
    b.push_back(0.2 + i / 1000.0);
  }
  EXPECT_NEAR(ksDistance(a, b), 0.2, 2e-3);
}

TEST(KsDistance, RefusesBadSamples) {
  EXPECT_THROW(ksDistance({}, {1.0}), std::invalid_argument);
  EXPECT_THROW(ksDistance({1.0}, {NAN}), std::invalid_argument);
  EXPECT_THROW(ksDistance(WeightedSample{{1.0}, {-1.0}}, WeightedSample::unweighted({1.0})), std::invalid_argument);
  EXPECT_THROW(ksDistance(WeightedSample{{1.0, 2.0}, {1.0}}, WeightedSample::unweighted({1.0})), std::invalid_argument);
  EXPECT_THROW(ksDistance(WeightedSample{{1.0}, {0.0}}, WeightedSample::unweighted({1.0})), std::invalid_argument);
}
