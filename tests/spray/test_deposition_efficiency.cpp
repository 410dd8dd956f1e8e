// Eq. (11)-(14) and Eq. (15): bounds, limits and known values.
#include <gtest/gtest.h>

#include <cmath>

#include "spray/Coverage.hpp"
#include "spray/DepositionEfficiency.hpp"

using namespace rcfd;

TEST(DepositionEfficiency, AlwaysInUnitIntervalAndFinite) {
  const DepositionConstants c;  // the paper's materials
  for (const std::string model : {"exponential", "linear_clipped"}) {
    auto m = DepositionModelRegistry::create(model);
    for (double alpha = 0.0; alpha <= 0.74 + 1e-12; alpha += 0.0074) {
      // St = rho_D d_D^2 slip / (9 rho_G nu_G d_P): slip up to 1e6 / St-per-slip covers St in [0, 1e6];
      // Re_m = alpha_G slip d_P / nu_G covers [0, 1e5] on the way.
      for (double slip : {0.0, 1e-9, 1e-3, 0.1, 1.0, 10.0, 100.0, 833.0, 1e4, 1e6}) {
        for (double dt : {1e-5, 5e-3, 1.0}) {
          const double eta = m->efficiency({alpha, slip, dt}, c);
          ASSERT_TRUE(std::isfinite(eta)) << model << " alpha " << alpha << " slip " << slip;
          ASSERT_GE(eta, 0.0);
          ASSERT_LE(eta, 1.0);
          if (slip == 0.0 || alpha == 0.0) ASSERT_EQ(eta, 0.0) << model;
        }
      }
    }
  }
}

TEST(DepositionEfficiency, HappelParameterFiniteOverThePackingRange) {
  EXPECT_DOUBLE_EQ(happelParameter(0.0), 1.0);  // (6 - 0) / (6 - 0 + 0 - 0)
  double previous = 1.0;
  for (double a = 0.001; a <= kMaxPackingForDeposition; a += 0.001) {
    const double A = happelParameter(a);
    ASSERT_TRUE(std::isfinite(A)) << a;
    ASSERT_GT(A, previous - 1e-12) << "A grows with alpha_P";
    previous = A;
  }
  EXPECT_TRUE(std::isfinite(happelParameter(0.99)));  // clamped to the packing limit, never 0/0
}

TEST(DepositionEfficiency, ExponentialEqualsEquation11ForSmallEta) {
  const DepositionConstants c;
  auto exponential = DepositionModelRegistry::create("exponential");
  auto linear = DepositionModelRegistry::create("linear_clipped");
  const DepositionInput small{0.05, 0.5, 1e-5};
  const double e = exponential->efficiency(small, c), l = linear->efficiency(small, c);
  ASSERT_GT(l, 0.0);
  ASSERT_LT(l, 1e-2);
  EXPECT_NEAR(e, l, 0.01 * l);
  // Where Eq. (11) exceeds 1 (dense spout, dt = 5 ms) the paper's form clips, the default saturates.
  const DepositionInput dense{0.5, 10.0, 5e-3};
  EXPECT_EQ(linear->efficiency(dense, c), 1.0);
  EXPECT_LT(exponential->efficiency(dense, c), 1.0);
  EXPECT_GT(exponential->efficiency(dense, c), 0.99);
}

TEST(DepositionEfficiency, FilterCoefficientFollowsEquations12And13) {
  // Hand evaluation at alpha_P = 0.3, slip 5 m/s with the paper's materials.
  const DepositionConstants c;
  const double alpha = 0.3, slip = 5.0;
  const double st = c.dropletDensity * c.dropletDiameter * c.dropletDiameter * slip /
                    (9.0 * c.gasDensity * c.gasViscosity * c.particleDiameter);
  const double a13 = std::cbrt(alpha), a53 = std::pow(alpha, 5.0 / 3.0);
  const double A = (6 - 6 * a53) / (6 - 9 * a13 + 9 * a53 - 6 * alpha * alpha);
  const double reM = (1 - alpha) * slip * c.particleDiameter / c.gasViscosity;
  const double stEff = st / 2 * (A + 1.14 * std::pow(reM, 0.2) * std::pow(1 - alpha, -1.5));
  const double lambda = std::pow(stEff, 3.2) / (std::pow(stEff, 3.2) + 4.3);
  EXPECT_NEAR(filterCoefficient({alpha, slip, 0.0}, c), lambda, 1e-12);
  EXPECT_GT(lambda, 0.0);
  EXPECT_LT(lambda, 1.0);
}

TEST(Coverage, Equation15AndItsLimits) {
  const double f = singleDropletCoverage(40e-6, 1.8e-3);
  EXPECT_NEAR(f, std::pow(40e-6 / 3.6e-3, 2), 1e-18);
  EXPECT_EQ(coverage(0.0, f), 0.0);
  EXPECT_NEAR(coverage(1.0, f), f, 1e-15);
  EXPECT_NEAR(coverage(1.89e4, f), 1.0 - std::pow(1.0 - f, 1.89e4), 1e-12);
  EXPECT_NEAR(coverage(1.89e4, f), 0.903, 0.005);  // the paper's ~90% after one hour
  EXPECT_LE(coverage(1e12, f), 1.0);
}
