// The choice of D0 from the scores: penalty minimum and the paper's rule, and the job options.
#include <gtest/gtest.h>

#include "analysis/CalibrationSelection.hpp"
#include "core/Errors.hpp"

using namespace rcfd;
using namespace rcfd::analysis;

namespace {

/// Scores of one run: penalty, instantaneous RMS over its counting floor, mean stay, KS distance and
/// the mean stay's and crossing rate's relative errors against the reference.
D0Scores score(double d0, double penalty, double rmsOverFloor, double rtdMean, std::optional<double> ks,
               double meanError = 0.0, double rateError = 0.0) {
  D0Scores s;
  s.d0 = d0;
  s.penalty = penalty;
  s.countingFloorRms = 0.05;
  s.instantaneousRms = rmsOverFloor * 0.05;
  s.rtdMean = rtdMean;
  s.stays = 100;
  s.ksDistance = ks;
  if (ks) s.rtdMeanRelativeError = meanError, s.crossingRateRelativeError = rateError;
  return s;
}

/// The paper's pattern: penalty minimum at 1e-4, bed shape and RTD agreeing from 5e-4 on.
std::vector<D0Scores> paperLike() {
  return {score(0.0, 0.020, 3.0, 0.05, 0.60, -0.5, 0.4), score(1e-5, 0.012, 2.0, 0.08, 0.40, -0.3, 0.3),
          score(1e-4, 0.006, 1.5, 0.10, 0.20, -0.1, 0.1), score(5e-4, 0.007, 1.2, 0.11, 0.08, 0.02, -0.03),
          score(1e-3, 0.008, 1.1, 0.11, 0.07, 0.01, -0.02), score(1e-2, 0.010, 1.15, 0.11, 0.09, 0.03, 0.05)};
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
  wide.fieldRmsTolerance = 0.55;     // 1e-4's 1.5 x the floor now counts as the right shape...
  wide.ksThreshold = 0.25;           // ...its KS 0.2 as agreeing residence times...
  wide.rtdRelativeTolerance = 0.15;  // ...and its 10 % errors of the mean and the crossing rate
  EXPECT_EQ(s[selectD0(s, wide, true).selected].d0, 1e-4);
  SelectionOptions strict;
  strict.ksThreshold = 0.075;  // only 1e-3 passes
  EXPECT_EQ(s[selectD0(s, strict, true).selected].d0, 1e-3);
  auto rate = s;
  rate[3].crossingRateRelativeError = -0.12;  // 5e-4 crosses 12 % too rarely
  EXPECT_EQ(rate[selectD0(rate, SelectionOptions{}, true).selected].d0, 1e-3);
}

TEST(Selection, AnOptimumAtTheUpperEndIsFlagged) {
  auto s = paperLike();
  EXPECT_FALSE(selectD0(s, SelectionOptions{}, true).atUpperEnd);
  for (auto& x : s) x.ksDistance = 0.3;  // no RTD agrees: 1e-2 is the lowest passing bed shape? no: 5e-4
  EXPECT_FALSE(selectD0(s, SelectionOptions{}, true).atUpperEnd);
  auto falling = paperLike();
  falling[5].penalty = 0.001;  // the penalty falls to the last value
  EXPECT_TRUE(selectD0(falling, SelectionOptions{}, true).atUpperEnd);
  auto onlyTop = paperLike();
  for (std::size_t i = 0; i + 1 < onlyTop.size(); ++i) onlyTop[i].instantaneousRms = 0.1;  // 2 x the floor
  const Selection sel = selectD0(onlyTop, SelectionOptions{}, true);
  EXPECT_EQ(onlyTop[sel.selected].d0, 1e-2);
  EXPECT_TRUE(sel.atUpperEnd);
}

TEST(Selection, WithoutReferenceUsesTheMeanResidenceTime) {
  auto s = paperLike();
  for (auto& x : s) x.ksDistance.reset(), x.rtdMeanRelativeError.reset(), x.crossingRateRelativeError.reset();
  const Selection sel = selectD0(s, SelectionOptions{}, false);
  // Best shape is 1e-3 (mean 0.11 s); 5e-4 is within 10 % of it and its RMS within 1.25 x the floor.
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
  EXPECT_NE(sel.reason.find("no value met the residence times"), std::string::npos) << sel.reason;
}

// When some D0 meets the residence times but not the bed shape, the reason names it instead of saying
// that none did.
TEST(Selection, NamesTheValuesWhoseResidenceTimesAloneAgree) {
  auto s = paperLike();
  for (auto& x : s) x.ksDistance = 0.9;
  s[1].ksDistance = 0.05, s[1].rtdMeanRelativeError = 0.01, s[1].crossingRateRelativeError = 0.02;  // 1e-5: 2 x the floor
  const Selection sel = selectD0(s, SelectionOptions{}, true);
  EXPECT_FALSE(sel.ruleSatisfied);
  EXPECT_TRUE(sel.residenceTimesAgree[1]);
  EXPECT_EQ(sel.reason.find("no value met"), std::string::npos) << sel.reason;
  EXPECT_NE(sel.reason.find("agree at D0 = 1e-05 m2/s, whose bed shape does not"), std::string::npos) << sel.reason;
}

// Where no D0 reaches the bed shape, the residence times decide: the best-shaped D0 among those whose
// residence times agree, not the best-shaped of all, whose stays may have drifted away.
TEST(Selection, WithoutAnAgreeingBedShapeTheResidenceTimesDecide) {
  auto s = paperLike();
  for (auto& x : s) x.instantaneousRms = 2.0 * x.instantaneousRms;  // every run 2.2-6 x its floor...
  s[5].instantaneousRms = 1.9 * s[5].countingFloorRms;  // ...1e-2 the best shape, 1.9 x...
  s[5].ksDistance = 0.15;                                // ...but its stays are off
  Selection sel = selectD0(s, SelectionOptions{}, true);
  EXPECT_FALSE(sel.ruleSatisfied);
  EXPECT_EQ(s[sel.selected].d0, 1e-3) << sel.reason;  // 2.2 x the floor against 5e-4's 2.4 x
  EXPECT_NE(sel.reason.find("best bed shape among those whose residence times agree"), std::string::npos)
      << sel.reason;
  for (auto& x : s) x.ksDistance = 0.9;  // none agrees: the best shape of all
  sel = selectD0(s, SelectionOptions{}, true);
  EXPECT_EQ(s[sel.selected].d0, 1e-2) << sel.reason;
  s[4].instantaneousRms = 1.2 * s[4].countingFloorRms;  // 1e-3's shape agrees: the lowest that does
  EXPECT_EQ(s[selectD0(s, SelectionOptions{}, true).selected].d0, 1e-3);
}

// The scores of the 3D ProCell bed without plates (docs/paper/no-plates-cal-summary.json, 472,850
// tracers): no bed shape within 1.25 x its floor, the residence times agreeing from 1e-4 to 3e-2 and the
// stays 12 % short at the top of the sweep, where the bed shape is best. The selection stays inside.
TEST(Selection, TheProCellSweepSelectsInsideIt) {
  struct Row { double d0, penalty, rmsOverFloor, mean, ks, meanError, rateError; };
  const Row rows[] = {{0, 0.00230277, 5.17, 0.066214, 0.02982, -0.02664, -0.101},
                      {1e-05, 0.00229591, 5.129, 0.066263, 0.02931, -0.02591, -0.1008},
                      {1e-4, 0.00223141, 4.952, 0.066202, 0.0302, -0.02682, -0.09993},
                      {5e-4, 0.0020953, 4.59, 0.066162, 0.03026, -0.0274, -0.09819},
                      {1e-3, 0.00197659, 4.319, 0.066118, 0.03044, -0.02804, -0.09585},
                      {1e-2, 0.0014123, 3.15, 0.065237, 0.03507, -0.04097, -0.0739},
                      {3e-2, 0.00116727, 2.566, 0.063552, 0.04505, -0.06572, -0.0409},
                      {0.09, 0.000969165, 2.048, 0.059941, 0.06906, -0.1187, 0.01805},
                      {0.09425, 0.000962832, 2.028, 0.05971, 0.07086, -0.1222, 0.02192}};
  std::vector<D0Scores> s;
  for (const Row& r : rows) s.push_back(score(r.d0, r.penalty, r.rmsOverFloor, r.mean, r.ks, r.meanError, r.rateError));
  const Selection sel = selectD0(s, SelectionOptions{}, true);
  EXPECT_EQ(s[sel.selected].d0, 3e-2) << sel.reason;
  EXPECT_EQ(s[sel.penaltyMinimum].d0, 0.09425);
  EXPECT_TRUE(sel.atUpperEnd);  // the penalty minimum is still the top
  EXPECT_FALSE(sel.residenceTimesAgree[1]);  // 1e-5 crosses 10.08 % too rarely
  EXPECT_TRUE(sel.residenceTimesAgree[2]);
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
  EXPECT_EQ(defaults.ksThreshold, 0.10);
  EXPECT_TRUE(defaults.extendSweep);
  EXPECT_EQ(defaults.sweepFactor, 3.0);
  EXPECT_EQ(defaults.rtdRelativeTolerance, 0.10);
  const auto o = selectionOptionsFrom({{"calibration", {{"ks_threshold", 0.3}, {"field_rms_tolerance", 0.5}}}});
  EXPECT_EQ(o.ksThreshold, 0.3);
  EXPECT_EQ(o.fieldRmsTolerance, 0.5);
  EXPECT_EQ(o.rtdRelativeTolerance, 0.10);
  EXPECT_FALSE(selectionOptionsFrom({{"calibration", {{"extend_sweep", false}}}}).extendSweep);
  try {
    selectionOptionsFrom({{"calibration", {{"sweep_factor", 1.0}}}});
    FAIL() << "accepted sweep_factor 1";
  } catch (const InputError& e) {
    EXPECT_EQ(e.violations()[0].pointer, "/calibration/sweep_factor");
  }
  try {
    selectionOptionsFrom({{"calibration", {{"ks_threshold", 1.5}}}});
    FAIL() << "accepted ks_threshold 1.5";
  } catch (const InputError& e) {
    ASSERT_EQ(e.violations().size(), 1u);
    EXPECT_EQ(e.violations()[0].pointer, "/calibration/ks_threshold");
    EXPECT_NE(e.violations()[0].message.find("(0, 1]"), std::string::npos) << e.violations()[0].message;
  }
}
