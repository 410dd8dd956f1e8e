// Sampling criterion, Eq. (8), against analytic signals.
#include <gtest/gtest.h>

#include "../fields/FieldTestUtil.hpp"
#include "recurrence/SamplingCriterion.hpp"

using namespace rcfd;
using namespace rcfd::test;

namespace {
// u_p.y = A_c sin(w_c t) with 200 frames per period of the slowest cell; w_c = w (1 + c % 3).
std::shared_ptr<FieldDatabase> sineDb(double dt, double omega, int frames) {
  const CartesianGrid g = smallGrid(4, 3, 2);
  return makeAnalyticDatabase(g, variedFluid(g, false), dt, frames, [&](int, double t, FieldFrame& f) {
    for (std::int64_t c = 0; c < g.cellCount(); ++c) {
      const double w = omega * double(1 + c % 3);
      f.alpha_p[std::size_t(c)] = 0.3f;  // particles in every cell: the reader keeps u_P as written
      f.u_p[std::size_t(3 * c + 1)] = float((1.0 + 0.1 * double(c)) * std::sin(w * t));
    }
  });
}
}  // namespace

// gamma = A sin(w t): sqrt(<gamma^2>/<gamma_dot^2>) = 1/w; central differences give
// A w cos(w t) sin(w dt)/(w dt), so the discrete bound is (1/w) (w dt / sin(w dt)).
TEST(SamplingCriterion, SineGivesOneOverOmega) {
  const double period = 1.0, dt = period / 200.0, omega = 2.0 * M_PI / period;
  auto db = sineDb(dt, omega, 802);  // interior frames 1..800: four whole periods
  std::vector<SamplingProbe> probes{{"slow", Eigen::Vector3d(-0.015, 0.005, 0.005)}};  // cell (0, 0, 0)
  const SamplingReport r = samplingCriterion(*db, "u_p.y", probes);
  ASSERT_EQ(r.points.size(), 1u);
  const double discrete = (1.0 / omega) * (omega * dt / std::sin(omega * dt));
  EXPECT_NEAR(r.points[0].bound, discrete, 1e-4 * discrete);
  EXPECT_NEAR(r.points[0].bound, 1.0 / omega, 1e-3 / omega);
  EXPECT_NEAR(r.points[0].rms, 1.0 / std::sqrt(2.0), 1e-4);
  EXPECT_TRUE(r.satisfied);
  EXPECT_DOUBLE_EQ(r.largestAdmissibleDtRec, r.points[0].bound);

  // Over all cells the fastest cells (3 w) set the limit.
  const SamplingReport all = samplingCriterion(*db, "u_p.y");
  EXPECT_TRUE(all.allCells);
  EXPECT_EQ(all.pointsConsidered, 24);
  const double fastest = (1.0 / (3 * omega)) * (3 * omega * dt / std::sin(3 * omega * dt));
  EXPECT_NEAR(all.largestAdmissibleDtRec, fastest, 1e-4 * fastest);
  const auto& k = all.strictest.cell;
  EXPECT_EQ(db->grid().flatIndex(k[0], k[1], k[2]) % 3, 2);  // a cell with w_c = 3 w
}

TEST(SamplingCriterion, StrictInequalityAtTheResolutionLimit) {
  // gamma = 0, 1, 0, -1, ... (a quarter period per frame): the bound equals dt exactly, and Eq. (8)
  // demands dt_rec < bound.
  std::vector<double> gamma;
  for (int n = 0; n < 42; ++n) gamma.push_back(n % 4 == 1 ? 1.0 : (n % 4 == 3 ? -1.0 : 0.0));
  EXPECT_DOUBLE_EQ(samplingBound(gamma, 0.5), 0.5);
  const CartesianGrid g = smallGrid(2, 2, 2);
  // A velocity component carries the signal: alpha_P must stay a volume fraction in [0, 1].
  auto db = makeAnalyticDatabase(g, variedFluid(g, false), 0.5, 42, [&](int n, double, FieldFrame& f) {
    for (std::int64_t c = 0; c < g.cellCount(); ++c) {
      f.alpha_p[std::size_t(c)] = 0.3f;  // particles in every cell: the reader keeps u_P as written
      f.u_p[3 * std::size_t(c)] = float(gamma[std::size_t(n)]);
    }
  });
  const SamplingReport r = samplingCriterion(*db, "u_p.x");
  EXPECT_DOUBLE_EQ(r.largestAdmissibleDtRec, 0.5);
  EXPECT_FALSE(r.satisfied);
}

TEST(SamplingCriterion, ConstantFieldHasNoBoundAndProbesOutsideAreRefused) {
  auto db = sineDb(0.01, 1.0, 10);
  const SamplingReport r = samplingCriterion(*db, "u_g.x");  // all zero
  EXPECT_EQ(r.pointsWithoutVariation, r.pointsConsidered);
  EXPECT_TRUE(std::isinf(r.largestAdmissibleDtRec));
  EXPECT_TRUE(r.satisfied);
  std::vector<SamplingProbe> outside{{"far", Eigen::Vector3d(1.0, 0.0, 0.0)}};
  EXPECT_NE(expectInputError([&] { samplingCriterion(*db, "u_p.y", outside); }, "/probes/0/position"), "NO EXCEPTION");
  EXPECT_NE(expectInputError([&] { samplingCriterion(*db, "u_p.q"); }, "--sampling-field"), "NO EXCEPTION");
  EXPECT_THROW(samplingBound({1.0, 2.0}, 0.1), InputError);
}

TEST(SamplingCriterion, ProbesFromTheSceneJson) {
  const auto probes = probesFromSceneJson(
      R"({"probes": [{"name": "spout", "position": [0, 0.075, 0.05]}, {"position": [0.1, 0.2, 0.1]}]})");
  ASSERT_EQ(probes.size(), 2u);
  EXPECT_EQ(probes[0].name, "spout");
  EXPECT_DOUBLE_EQ(probes[0].position.y(), 0.075);
  EXPECT_TRUE(probesFromSceneJson("not json").empty());
  EXPECT_TRUE(probesFromSceneJson("{}").empty());
}
