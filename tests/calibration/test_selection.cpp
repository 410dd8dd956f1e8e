// The choice of D0 from the scores: penalty minimum and the paper's rule, and the job options.
#include <gtest/gtest.h>

#include "analysis/CalibrationSelection.hpp"
#include "core/Errors.hpp"

using namespace rcfd;
using namespace rcfd::analysis;

namespace {

D0Scores score(double d0, double penalty, double fieldRms, double rtdMean, std::optional<double> ks) {
  D0Scores s;
  s.d0 = d0;
  s.penalty = penalty;
  s.fieldRms = fieldRms;
  s.rtdMean = rtdMean;
  s.stays = 100;
  s.ksDistance = ks;
  return s;
}

/// The paper's pattern: penalty minimum at 1e-4, bed shape and RTD agreeing from 5e-4 on.
std::vector<D0Scores> paperLike() {
  return {score(0.0, 0.020, 0.20, 0.05, 0.60), score(1e-5, 0.012, 0.12, 0.08, 0.40),
          score(1e-4, 0.006, 0.07, 0.10, 0.20), score(5e-4, 0.007, 0.042, 0.11, 0.08),
          score(1e-3, 0.008, 0.040, 0.11, 0.07), score(1e-2, 0.010, 0.045, 0.11, 0.09)};
}

}  // namespace

TEST(Selection, PaperPatternWithReference) {
  const auto s = paperLike();
  const Selection sel = selectD0(s, SelectionOptions{}, true);
  EXPECT_EQ(s[sel.penaltyMinimum].d0, 1e-4);
  EXPECT_EQ(s[sel.selected].d0, 5e-4);
  EXPECT_TRUE(sel.ruleSatisfied);
  EXPECT_NE(sel.reason.find("D0 = 0.0005 m2/s is the lowest"), std::string::npos) << sel.reason;
  EXPECT_NE(sel.reason.find("penalty minimum"), std::string::npos) << sel.reason;
  EXPECT_EQ(sel.reason.find('\n'), std::string::npos);
}

TEST(Selection, OrderOfTheListDoesNotMatter) {
  auto s = paperLike();
  std::reverse(s.begin(), s.end());
  const Selection sel = selectD0(s, SelectionOptions{}, true);
  EXPECT_EQ(s[sel.selected].d0, 5e-4);
  EXPECT_EQ(s[sel.penaltyMinimum].d0, 1e-4);
}

TEST(Selection, ThresholdsMoveTheChoice) {
  const auto s = paperLike();
  SelectionOptions wide;
  wide.fieldRmsTolerance = 1.0;  // 1e-4's 0.07 <= 2 x 0.04 now counts as the right shape...
  wide.ksThreshold = 0.25;       // ...and its KS 0.2 as agreeing residence times
  EXPECT_EQ(s[selectD0(s, wide, true).selected].d0, 1e-4);
  SelectionOptions strict;
  strict.ksThreshold = 0.075;  // only 1e-3 passes
  EXPECT_EQ(s[selectD0(s, strict, true).selected].d0, 1e-3);
}

TEST(Selection, WithoutReferenceUsesTheMeanResidenceTime) {
  auto s = paperLike();
  for (auto& x : s) x.ksDistance.reset();
  const Selection sel = selectD0(s, SelectionOptions{}, false);
  // Best shape is 1e-3 (mean 0.11 s); 5e-4 is within 10 % of it and of the best field RMS.
  EXPECT_EQ(s[sel.selected].d0, 5e-4);
  EXPECT_NE(sel.reason.find("no reference"), std::string::npos) << sel.reason;
}

TEST(Selection, FallsBackToBedShapeWhenNoRunMeetsBoth) {
  auto s = paperLike();
  for (auto& x : s) x.ksDistance = 0.9;
  const Selection sel = selectD0(s, SelectionOptions{}, true);
  EXPECT_FALSE(sel.ruleSatisfied);
  EXPECT_EQ(s[sel.selected].d0, 5e-4);
  EXPECT_NE(sel.reason.find("no D0 met both"), std::string::npos) << sel.reason;
}

TEST(Selection, RunWithoutStaysHasNoAgreeingResidenceTimes) {
  auto s = paperLike();
  s[3].stays = 0;
  const Selection sel = selectD0(s, SelectionOptions{}, true);
  EXPECT_FALSE(sel.residenceTimesAgree[3]);
  EXPECT_EQ(s[sel.selected].d0, 1e-3);
}

TEST(Selection, OptionsFromTheJobDocument) {
  const auto defaults = selectionOptionsFrom(nlohmann::json::object());
  EXPECT_EQ(defaults.fieldRmsTolerance, 0.25);
  EXPECT_EQ(defaults.ksThreshold, 0.15);
  EXPECT_EQ(defaults.rtdRelativeTolerance, 0.10);
  const auto o = selectionOptionsFrom({{"calibration", {{"ks_threshold", 0.3}, {"field_rms_tolerance", 0.5}}}});
  EXPECT_EQ(o.ksThreshold, 0.3);
  EXPECT_EQ(o.fieldRmsTolerance, 0.5);
  EXPECT_EQ(o.rtdRelativeTolerance, 0.10);
  try {
    selectionOptionsFrom({{"calibration", {{"ks_threshold", 1.5}}}});
    FAIL() << "accepted ks_threshold 1.5";
  } catch (const InputError& e) {
    ASSERT_EQ(e.violations().size(), 1u);
    EXPECT_EQ(e.violations()[0].pointer, "/calibration/ks_threshold");
    EXPECT_NE(e.violations()[0].message.find("(0, 1]"), std::string::npos) << e.violations()[0].message;
  }
}
