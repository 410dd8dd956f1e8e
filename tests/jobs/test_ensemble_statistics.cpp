// The ensemble's arithmetic: Student t quantiles, the spread of member values, the members' seeds and
// the summary block built from member summaries.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "analysis/EnsembleStatistics.hpp"
#include "jobs/Ensemble.hpp"

using nlohmann::json;

TEST(EnsembleStatistics, StudentTQuantilesMatchTheTables) {
  // Two-sided 95 % (p = 0.975) from standard tables, and the normal limit.
  const std::pair<int, double> table[] = {{1, 12.7062047}, {2, 4.30265273}, {3, 3.18244631}, {4, 2.77644511},
                                          {7, 2.36462425}, {15, 2.13144955}, {30, 2.04227246}, {63, 1.99834054}};
  for (const auto& [dof, t] : table) EXPECT_NEAR(rcfd::analysis::studentTQuantile(0.975, dof), t, 1e-6) << dof;
  EXPECT_NEAR(rcfd::analysis::studentTQuantile(0.95, 10), 1.81246112, 1e-6);
  EXPECT_NEAR(rcfd::analysis::studentTQuantile(0.025, 3), -3.18244631, 1e-6);
  EXPECT_NEAR(rcfd::analysis::studentTQuantile(0.975, 100000), 1.95996398, 1e-4);
  EXPECT_EQ(rcfd::analysis::studentTQuantile(0.5, 5), 0.0);
}

TEST(EnsembleStatistics, SpreadIsTheSampleDeviationAndTheStandardErrorOfTheMean) {
  const std::vector<double> v = {1.0, 2.0, 4.0, 9.0};
  const auto s = rcfd::analysis::spreadOf(v);
  EXPECT_EQ(s.members, 4);
  EXPECT_DOUBLE_EQ(s.mean, 4.0);
  const double sd = std::sqrt((9.0 + 4.0 + 0.0 + 25.0) / 3.0);
  EXPECT_NEAR(s.sd, sd, 1e-12);
  EXPECT_NEAR(s.sem, sd / 2.0, 1e-12);
  EXPECT_NEAR(s.ciLow, 4.0 - 3.18244631 * sd / 2.0, 1e-6);
  EXPECT_NEAR(s.ciHigh, 4.0 + 3.18244631 * sd / 2.0, 1e-6);
  EXPECT_EQ(s.min, 1.0);
  EXPECT_EQ(s.max, 9.0);
  const auto one = rcfd::analysis::spreadOf({3.0});
  EXPECT_EQ(one.sd, 0.0);
  EXPECT_EQ(one.ciLow, 3.0);
  EXPECT_EQ(one.ciHigh, 3.0);
}

TEST(EnsembleStatistics, SeedsStartWithTheJobSeedAndAreDistinctStableAndJsonExact) {
  const auto seeds = rcfd::ensembleSeeds(17, 64);
  ASSERT_EQ(seeds.size(), 64u);
  EXPECT_EQ(seeds[0], 17u);
  EXPECT_EQ(std::set<std::uint64_t>(seeds.begin(), seeds.end()).size(), 64u);
  for (const auto s : seeds) EXPECT_LT(s, std::uint64_t(1) << 53);
  // Member k's seed does not depend on K: the first members of a larger ensemble are the smaller one.
  const auto four = rcfd::ensembleSeeds(17, 4);
  EXPECT_TRUE(std::equal(four.begin(), four.end(), seeds.begin()));
  EXPECT_NE(rcfd::ensembleSeeds(18, 2)[1], seeds[1]);
}

TEST(EnsembleStatistics, SummaryBlockGivesEveryStatisticAndTheHistogramBand) {
  std::vector<json> members;
  const std::vector<std::vector<int>> counts = {{5, 3, 2}, {6, 2, 2}, {4, 4, 2}};
  for (int k = 0; k < 3; ++k) {
    members.push_back({{"coverage",
                        {{"mean", 0.1 * (k + 1)},
                         {"median", 0.2},
                         {"p10", 0.0},
                         {"p90", 0.5},
                         {"histogram", {{"edges", {0.0, 0.5, 0.75, 1.0}}, {"counts", counts[std::size_t(k)]}}}}},
                       {"overspray_fraction", 0.01 * k},
                       {"holdup", {{"mean", 100.0 + k}}},
                       {"stay_comparison", nullptr}});
  }
  const json block = rcfd::ensembleSummary(members, rcfd::ensembleSeeds(1, 3));
  EXPECT_EQ(block["members"], 3);
  EXPECT_NEAR(block["coverage"]["mean"]["mean"].get<double>(), 0.2, 1e-15);
  EXPECT_NEAR(block["coverage"]["mean"]["sd"].get<double>(), 0.1, 1e-15);
  EXPECT_EQ(block["coverage"]["median"]["sd"].get<double>(), 0.0);
  EXPECT_EQ(block["coverage"]["mean"]["values"].size(), 3u);
  EXPECT_NEAR(block["interval"]["t"].get<double>(), 4.30265273, 1e-6);
  EXPECT_NEAR(block["overspray_fraction"]["max"].get<double>(), 0.02, 1e-15);
  EXPECT_NEAR(block["holdup"]["mean"]["mean"].get<double>(), 101.0, 1e-12);
  EXPECT_FALSE(block.contains("stay_comparison"));  // null in the members: nothing to average
  EXPECT_FALSE(block.contains("residence_time"));
  const json& h = block["coverage"]["histogram"];
  EXPECT_EQ(h["mean"], json({5.0, 3.0, 2.0}));
  EXPECT_EQ(h["sd"][2].get<double>(), 0.0);
  EXPECT_NEAR(h["sem"][0].get<double>(), 1.0 / std::sqrt(3.0), 1e-12);
  EXPECT_EQ(h["min"], json({4.0, 2.0, 2.0}));
  EXPECT_EQ(h["max"], json({6.0, 4.0, 2.0}));
  EXPECT_EQ(h["member_counts"].size(), 3u);
}
