// EtaEstimator: the remaining time from the rate of the last window of progress reports, limited to a
// factor 2 per minute once it has run 30 s. Synthetic timelines (one report per second) with a known
// end: a slow fill then a fast sampling phase, a stall, a restart from a checkpoint.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <vector>

#include "jobs/EtaEstimator.hpp"
#include "jobs/Progress.hpp"

namespace rcfd {
namespace {

/// A stretch of a timeline: `seconds` of wall time over which the fraction grows by `gained` at a
/// constant rate (0: a stall).
struct Stretch {
  double seconds;
  double gained;
};

struct Report {
  double t;         ///< wall time [s]
  double fraction;
  double truth;     ///< wall seconds until the timeline ends
  double eta;       ///< the estimator's answer
  double raw;       ///< its unlimited estimate
};

/// Feeds `eta` one report per second of the timeline that starts at fraction `start` and wall time 0.
std::vector<Report> play(EtaEstimator& eta, const std::vector<Stretch>& stretches, double start = 0.0) {
  double end = 0.0;
  for (const auto& s : stretches) end += s.seconds;
  std::vector<Report> out;
  double t0 = 0.0, f0 = start;
  for (const auto& s : stretches) {
    for (int k = 1; k <= int(std::lround(s.seconds)); ++k) {
      const double t = t0 + k, f = std::min(1.0, f0 + s.gained * k / s.seconds);
      const double e = eta.update(t, f);
      out.push_back({t, f, end - t, e, eta.raw()});
    }
    t0 += s.seconds;
    f0 += s.gained;
  }
  return out;
}

/// The promise of EtaEstimator.hpp between any two estimates at most a minute apart after the first
/// `settle` seconds: at most twice the earlier one (or the floor), at least half of it less the time between.
void expectFactorTwoPerMinute(const std::vector<Report>& reports, double settle = 30.0, double floor = 10.0) {
  int checked = 0;
  for (std::size_t i = 0; i < reports.size(); ++i) {
    const Report& a = reports[i];
    if (a.t < settle || a.eta < 0.0) continue;
    for (std::size_t j = i + 1; j < reports.size() && reports[j].t - a.t <= 60.0; ++j) {
      const Report& b = reports[j];
      ASSERT_GE(b.eta, 0.0) << "t = " << b.t;
      const double span = b.t - a.t, growth = std::exp2(span / 60.0);
      ASSERT_LE(b.eta, growth * std::max(a.eta, floor) * (1 + 1e-12)) << "from t = " << a.t << " to " << b.t;
      ASSERT_GE(b.eta, a.eta / growth - span - 1e-9) << "from t = " << a.t << " to " << b.t;
      ++checked;
    }
  }
  EXPECT_GT(checked, 0);
}

/// The largest factor by which the raw estimate changed within a minute (beyond the countdown).
double largestRawJump(const std::vector<Report>& reports, double after) {
  double worst = 1.0;
  for (std::size_t i = 0; i < reports.size(); ++i) {
    if (reports[i].t < after || reports[i].raw <= 0.0) continue;
    for (std::size_t j = i + 1; j < reports.size() && reports[j].t - reports[i].t <= 60.0; ++j) {
      if (reports[j].raw <= 0.0) continue;
      const double counted = reports[i].raw - (reports[j].t - reports[i].t);
      if (counted > 0.0) worst = std::max({worst, reports[j].raw / counted, counted / reports[j].raw});
    }
  }
  return worst;
}

/// Every estimate from wall time `from` to the end within `tolerance` seconds of the truth.
void expectTrueFrom(const std::vector<Report>& reports, double from, double tolerance) {
  int checked = 0;
  for (const auto& r : reports) {
    if (r.t < from) continue;
    ASSERT_NEAR(r.eta, r.truth, tolerance) << "t = " << r.t;
    ++checked;
  }
  EXPECT_GT(checked, 0);
}

TEST(EtaEstimator, SteadyProgressGivesTheRemainingTimeAtThatRate) {
  EtaEstimator eta;
  const auto reports = play(eta, {{100.0, 1.0}});  // 1 % per second
  EXPECT_EQ(reports[0].eta, -1.0);                  // 1 s of history is no estimate
  EXPECT_EQ(reports[3].eta, -1.0);
  expectTrueFrom(reports, 5.0, 1e-6);
  EXPECT_EQ(reports.back().eta, 0.0);  // done
}

TEST(EtaEstimator, ASlowFillThenAFastSamplingMovesAtMostAFactorTwoPerMinuteAndReachesTheTruth) {
  // The database job: 5 % of the fraction in 30 min of filling, the other 95 % in 2 h, so the
  // fill's rate predicts 9.5 h where 2 h are left. The raw estimate falls by more than 4x within a
  // minute of the switch; the reported one by at most 2x per minute, and then equals the truth.
  EtaEstimator eta;
  const auto reports = play(eta, {{1800.0, 0.05}, {7200.0, 0.95}});
  const Report& atSwitch = reports[1799];
  EXPECT_NEAR(atSwitch.eta, 0.95 / (0.05 / 1800.0), 1.0);
  EXPECT_NEAR(atSwitch.truth, 7200.0, 1e-9);
  EXPECT_GT(largestRawJump(reports, 30.0), 4.0);
  expectFactorTwoPerMinute(reports);
  // 4.75x at 2x per minute: a little over two minutes, then exact.
  expectTrueFrom(reports, 1800.0 + 240.0, 1e-6);
  // And it moves right away, downwards only.
  for (int k = 1; k < 240; ++k) EXPECT_LE(reports[1799 + k].eta, reports[1799 + k - 1].eta) << k;
  EXPECT_LT(reports[1800 + 60].eta, 0.6 * atSwitch.eta);
}

TEST(EtaEstimator, AFastStartThenASlowPhaseRisesAtMostAFactorTwoPerMinute) {
  EtaEstimator eta;
  const auto reports = play(eta, {{600.0, 0.5}, {6000.0, 0.5}});  // then 10x slower
  EXPECT_GT(largestRawJump(reports, 30.0), 4.0);
  expectFactorTwoPerMinute(reports);
  expectTrueFrom(reports, 600.0 + 360.0, 1e-6);
}

TEST(EtaEstimator, AStallRaisesTheEstimateGraduallyAndItRecoversAfterwards) {
  // 1 % per minute, with no progress for 10 minutes at 40 %.
  EtaEstimator eta;
  const auto reports = play(eta, {{2400.0, 0.4}, {600.0, 0.0}, {3600.0, 0.6}});
  expectFactorTwoPerMinute(reports);
  const Report& before = reports[2399];
  EXPECT_NEAR(before.eta, 3600.0, 1e-6);  // the stall is not foreseen
  // The estimate rises during the stall, never unknown, by at most 2x per minute.
  for (int k = 1; k < 600; ++k) {
    const Report& r = reports[2399 + k];
    EXPECT_GE(r.eta, reports[2399 + k - 1].eta - 1.0 - 1e-9) << k;
    EXPECT_LE(r.eta, std::exp2(k / 60.0) * before.eta * (1 + 1e-12)) << k;
  }
  EXPECT_GT(reports[2999].eta, 2.0 * before.eta);
  // Back at the old rate: the truth again within minutes.
  expectTrueFrom(reports, 3000.0 + 600.0, 1e-6);
}

TEST(EtaEstimator, AStoppedProcessGoesOnFromItsEstimateWhenContinued) {
  // 1 % per minute to 40 %; then the process is stopped for 25 min (no update at all) and goes on at
  // the same rate. Told of the stop, the estimate goes on from 60 min; not told, the first update
  // reads the stop as a stall and the estimate climbs far beyond the truth.
  auto run = [](bool told) {
    EtaEstimator eta;
    play(eta, {{2400.0, 0.4}});
    if (told) eta.skip(1500.0);
    std::vector<double> after;
    for (int k = 1; k <= 120; ++k) after.push_back(eta.update(2400.0 + 1500.0 + k, 0.4 + 0.01 * k / 60.0));
    return after;
  };
  const auto told = run(true), untold = run(false);
  for (int k = 1; k <= 120; ++k) EXPECT_NEAR(told[std::size_t(k - 1)], 3600.0 - k, 1e-6) << k;
  EXPECT_GT(untold.front(), 10.0 * 3600.0);
  EXPECT_GT(untold.back(), 2.0 * 3600.0);
}

TEST(Progress, ASigcontIsCounted) {
  ProgressReporter reporter(false, 1.0);  // counts SIGCONT from here on
  const std::uint64_t before = processContinuations();
  ASSERT_EQ(std::raise(SIGCONT), 0);
  EXPECT_EQ(processContinuations(), before + 1);
}

TEST(EtaEstimator, ARestartFromACheckpointUsesOnlyTheNewProcesssRate) {
  // The first process ran at 1 % per minute to 30 %; the resumed one, on a busier machine, at 0.5 %.
  EtaEstimator first;
  const auto before = play(first, {{1800.0, 0.3}});
  EXPECT_NEAR(before.back().eta, 4200.0, 1e-6);
  EtaEstimator resumed;
  resumed.restart(0.0, 0.3);
  const auto reports = play(resumed, {{8400.0, 0.7}}, 0.3);
  EXPECT_EQ(reports[0].eta, -1.0);
  EXPECT_EQ(reports[3].eta, -1.0);
  EXPECT_NEAR(reports[4].eta, reports[4].truth, 1e-6);
  expectFactorTwoPerMinute(reports);
  expectTrueFrom(reports, 5.0, 1e-6);
  // The same within one process: restart() forgets the rate before it.
  EtaEstimator same;
  play(same, {{600.0, 0.1}});
  same.restart(600.0, 0.1);
  EXPECT_EQ(same.update(601.0, 0.1 + 0.005 / 60.0), -1.0);
  for (int t = 602; t <= 700; ++t) same.update(double(t), 0.1 + 0.005 * (t - 600) / 60.0);
  EXPECT_NEAR(same.update(701.0, 0.1 + 0.005 * 101 / 60.0), (0.9 - 0.005 * 101 / 60.0) / (0.005 / 60.0), 1e-6);
}

TEST(EtaEstimator, AFractionThatGoesDownStartsOver) {
  // A calibration whose sweep grows by one D0: 6 of 6 runs done becomes 6 of 7.
  EtaEstimator eta;
  play(eta, {{600.0, 1.0 - 1e-9}});
  EXPECT_EQ(eta.update(601.0, 6.0 / 7.0), -1.0);
  double e = -1.0;
  for (int t = 602; t <= 700; ++t) e = eta.update(double(t), 6.0 / 7.0 + (t - 601) / 600.0 / 7.0);
  EXPECT_NEAR(e, (1.0 - (6.0 / 7.0 + 99 / 600.0 / 7.0)) * 600.0 * 7.0, 1e-6);
}

TEST(EtaEstimator, NoProgressAtAllIsNoEstimate) {
  EtaEstimator eta;
  eta.restart(0.0, 0.2);
  EXPECT_EQ(eta.update(0.0, 0.2), -1.0);
  for (int t = 1; t <= 120; ++t) EXPECT_EQ(eta.update(double(t), 0.2), -1.0) << t;
  // The first progress gives the raw estimate, from which the limit starts.
  EXPECT_NEAR(eta.update(130.0, 0.3), 0.7 / (0.1 / 130.0), 1e-6);
}

TEST(EtaEstimator, FollowsTheRateOfTheLastWindowNotTheAverageSinceTheStart) {
  // 50 % in 50 s, then 10x slower: the raw estimate follows within the window, and so, within the
  // limit, does the reported one.
  EtaEstimator eta;
  const auto reports = play(eta, {{50.0, 0.5}, {5000.0, 0.5}});
  const Report& r = reports[50 + 70 - 1];
  EXPECT_NEAR(r.raw, (1.0 - r.fraction) / 0.0001, 1e-6);  // the average since the start would say ~115 s
  expectFactorTwoPerMinute(reports);
  expectTrueFrom(reports, 50.0 + 600.0, 1e-6);
}

TEST(Progress, HumanDurations) {
  EXPECT_EQ(humanDuration(0.4), "0 s");
  EXPECT_EQ(humanDuration(59.4), "59 s");
  EXPECT_EQ(humanDuration(125.0), "2 min 05 s");
  EXPECT_EQ(humanDuration(36000.0 + 420.0), "10 h 07 min");
  EXPECT_EQ(humanDuration(-1.0), "?");
  EXPECT_EQ(humanDuration(std::nan("")), "?");
}

}  // namespace
}  // namespace rcfd
