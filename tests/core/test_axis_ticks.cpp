// Axis ticks at round numbers and durations as a person writes them (core/AxisTicks.hpp), and the axes
// every figure draws through SvgDocument::axes.

#include <gtest/gtest.h>

#include <regex>
#include <string>
#include <vector>

#include "core/AxisTicks.hpp"
#include "core/Svg.hpp"

using namespace rcfd;

TEST(AxisTicks, StepsAreOneTwoOrFiveTimesAPowerOfTen) {
  EXPECT_DOUBLE_EQ(niceStep(0.0123), 0.01);
  EXPECT_DOUBLE_EQ(niceStep(0.0615), 0.05);
  EXPECT_DOUBLE_EQ(niceStep(0.18), 0.2);
  EXPECT_DOUBLE_EQ(niceStep(3.0), 2.0);
  EXPECT_DOUBLE_EQ(niceStep(8.0), 10.0);
  EXPECT_DOUBLE_EQ(niceStep(420.0), 500.0);
}

TEST(AxisTicks, TheCoverageAxisTicksAtRoundNumbersInsideItsRange) {
  // The coverage figure's y range: the tallest bar's fraction times 1.1, here 0.3075.
  const std::vector<double> ticks = niceTicks(0.0, 0.3075, 5);
  ASSERT_EQ(ticks.size(), 7u);
  const double step = tickStep(ticks);
  EXPECT_DOUBLE_EQ(step, 0.05);
  std::vector<std::string> labels;
  for (double t : ticks) labels.push_back(tickLabel(t, step));
  EXPECT_EQ(labels, (std::vector<std::string>{"0", "0.05", "0.1", "0.15", "0.2", "0.25", "0.3"}));
  for (double t : ticks) {
    EXPECT_GE(t, 0.0);
    EXPECT_LE(t, 0.3075);
  }
}

TEST(AxisTicks, RangesOffZeroAndNegativeOnesKeepTheirMultiples) {
  const std::vector<double> ticks = niceTicks(-0.23, 0.41, 6);  // step 0.1
  std::vector<std::string> labels;
  for (double t : ticks) labels.push_back(tickLabel(t, tickStep(ticks)));
  EXPECT_EQ(labels, (std::vector<std::string>{"-0.2", "-0.1", "0", "0.1", "0.2", "0.3", "0.4"}));
  const std::vector<double> years = niceTicks(1013.0, 1098.0, 4);
  EXPECT_EQ(years, (std::vector<double>{1020, 1040, 1060, 1080}));
  EXPECT_EQ(tickLabel(1040, 20), "1040");
  EXPECT_EQ(tickLabel(2e-5, 1e-5), "2e-05");
  // A range whose ends are multiples of the step (a section figure's) keeps both ends.
  const std::vector<double> metres = niceTicks(-0.3, 0.6, 9);
  ASSERT_EQ(metres.size(), 10u);
  EXPECT_EQ(tickLabel(metres.front(), 0.1), "-0.3");
  EXPECT_EQ(tickLabel(metres.back(), 0.1), "0.6");
  EXPECT_TRUE(niceTicks(1.0, 1.0, 5).empty());
}

TEST(AxisTicks, DurationsReadAsAPersonWritesThem) {
  EXPECT_EQ(durationLabel(2.5), "2.5 s");
  EXPECT_EQ(durationLabel(0.25), "0.25 s");
  EXPECT_EQ(durationLabel(45.0), "45 s");
  EXPECT_EQ(durationLabel(600.0), "10 min");
  EXPECT_EQ(durationLabel(600.0000001), "10 min");
  EXPECT_EQ(durationLabel(90.0), "1 min 30 s");
  EXPECT_EQ(durationLabel(3600.0), "1 h");
  EXPECT_EQ(durationLabel(3599.9), "1 h");
  EXPECT_EQ(durationLabel(8100.0), "2 h 15 min");
}

TEST(AxisTicks, FigureAxesCarryTheRoundTicks) {
  SvgDocument svg(0.0, 1.0, 0.0, 0.3075, 640, 420, 55);
  svg.axes("phi", "fraction");
  const std::string text = svg.str();
  for (const char* label : {">0.05<", ">0.15<", ">0.3<", ">0.2<", ">0.4<", ">1<"})
    EXPECT_NE(text.find(label), std::string::npos) << label << "\n" << text;
  // Not the old fifths of the range (0.0615, 0.123, ...).
  EXPECT_EQ(text.find(">0.0615<"), std::string::npos);
  EXPECT_EQ(text.find(">0.123<"), std::string::npos);
}
