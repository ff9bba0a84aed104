// The smoothing function of eq. 9: closed forms of Remark 3.4 (with ERRATA item 1), the end
// conditions of eq. 4 and the values of eq. 10.
#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "posefair/core/spline_smoothing_function.hpp"

namespace posefair::geometric_splines {
namespace {

TEST(SmoothingFunction, ClosedFormsOfRemark34) {
  const SmoothingFunction k1(1), k2(2), k3(3);
  for (double u = -0.5; u <= 1.5; u += 0.0625) {
    EXPECT_NEAR(k1(u), u, 1e-15);
    EXPECT_NEAR(k2(u), u * u * (3.0 - 2.0 * u), 1e-14);  // ERRATA 1: 3 - 2t, not 3 2t
    EXPECT_NEAR(k3(u), u * u * u * (10.0 - 15.0 * u + 6.0 * u * u), 1e-13);
  }
}

TEST(SmoothingFunction, EndConditionsOfEq4AndValuesOfEq10) {
  for (int k = 1; k <= kMaxSplineOrder; ++k) {
    const SmoothingFunction phi(k);
    EXPECT_EQ(phi.coefficients().size(), 2 * k);
    EXPECT_NEAR(phi(0.0), 0.0, 1e-15) << k;
    EXPECT_NEAR(phi(1.0), 1.0, 1e-12) << k;
    for (int j = 1; j < k; ++j) {
      EXPECT_NEAR(phi.derivative(0.0, j), 0.0, 1e-12) << k << " " << j;
      EXPECT_NEAR(phi.derivative(1.0, j), 0.0, 1e-9 * factorial(j)) << k << " " << j;
    }
    // gamma from its definition; eq. 10.
    double inverse_gamma = 0.0;
    for (int l = 0; l < k; ++l) inverse_gamma += ((l % 2) ? -1.0 : 1.0) * binomial(k - 1, l) / (k + l);
    const double gamma = 1.0 / inverse_gamma;
    const double at0 = gamma * factorial(k - 1);
    EXPECT_NEAR(phi.derivative(0.0, k), at0, 1e-9 * std::abs(at0)) << k;
    EXPECT_NEAR(phi.derivative(1.0, k), ((k - 1) % 2 ? -1.0 : 1.0) * at0, 1e-9 * std::abs(at0)) << k;
    // phi' = gamma u^{k-1} (1-u)^{k-1}
    for (double u = 0.1; u < 1.0; u += 0.2)
      EXPECT_NEAR(phi.derivative(u, 1), gamma * std::pow(u * (1.0 - u), k - 1), 1e-11 * gamma) << k;
  }
}

TEST(SmoothingFunction, BlendWeightsAreTheStep3Products) {
  const SmoothingFunction phi(3);
  for (double u = 0.0; u <= 1.0; u += 0.125) {
    const double f = phi(u);
    const Eigen::Vector3d w = phi.blend_weights(u);
    EXPECT_NEAR(w[0], (1 - f) * (1 - f), 1e-14);
    EXPECT_NEAR(w[1], 2 * f * (1 - f), 1e-14);
    EXPECT_NEAR(w[2], f * f, 1e-14);
    EXPECT_NEAR(phi.blend_weights(u, 2).sum(), 0.0, 1e-11);  // the weights sum to 1 for every u
  }
}

TEST(SmoothingFunction, RejectsOrdersOutsideTheRange) {
  EXPECT_THROW(SmoothingFunction(0), std::invalid_argument);
  EXPECT_THROW(SmoothingFunction(kMaxSplineOrder + 1), std::invalid_argument);
}

}  // namespace
}  // namespace posefair::geometric_splines
