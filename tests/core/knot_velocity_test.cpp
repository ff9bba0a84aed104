// Knot velocity estimators: the polynomial degree each one reproduces exactly on non-uniform
// knots (ends included), and their neighbourhoods.
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "posefair/core/knot_velocity.hpp"

namespace posefair::geometric_splines {
namespace {

using V2 = Eigen::Vector2d;

// x(t) = a + b t + c t^2 sampled at non-uniform times; the estimate at each knot vs x'(t_i).
double worst_error(KnotVelocityOptions o, double c) {
  const std::vector<double> t{0.0, 0.1, 0.35, 0.4, 0.9, 1.0, 1.6, 1.65, 2.0};
  const V2 a(1.0, -2.0), b(0.5, 3.0), cc(c, -c);
  double worst = 0.0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const auto [first, last] = knot_velocity_neighbourhood(o, i, t.size());
    std::vector<double> dt;
    std::vector<V2> x;
    const V2 xi = a + b * t[i] + cc * t[i] * t[i];
    for (std::size_t j = first; j <= last; ++j) {
      dt.push_back(t[j] - t[i]);
      x.push_back(a + b * t[j] + cc * t[j] * t[j] - xi);
    }
    const V2 v = estimate_knot_velocity<2>(o.estimator, dt, x);
    worst = std::max(worst, (v - (b + 2 * cc * t[i])).norm());
  }
  return worst;
}

TEST(KnotVelocity, CentralDifferenceIsExactForLinesOnly) {
  KnotVelocityOptions o{KnotVelocityEstimator::CentralDifference, 3};
  EXPECT_LT(worst_error(o, 0.0), 1e-13);
  EXPECT_GT(worst_error(o, 1.0), 0.05);
}

TEST(KnotVelocity, BesselAndTheFitAreExactForParabolas) {
  EXPECT_LT(worst_error({KnotVelocityEstimator::Bessel, 3}, 1.0), 1e-12);
  for (int w = 1; w <= 4; ++w) EXPECT_LT(worst_error({KnotVelocityEstimator::LocalQuadraticFit, w}, 1.0), 1e-11) << w;
}

TEST(KnotVelocity, Neighbourhoods) {
  const KnotVelocityOptions central{KnotVelocityEstimator::CentralDifference, 3};
  const KnotVelocityOptions bessel{KnotVelocityEstimator::Bessel, 3};
  const KnotVelocityOptions fit{KnotVelocityEstimator::LocalQuadraticFit, 2};
  using Range = std::pair<std::size_t, std::size_t>;
  EXPECT_EQ(knot_velocity_neighbourhood(central, 0, 10), Range(0, 1));
  EXPECT_EQ(knot_velocity_neighbourhood(central, 5, 10), Range(4, 6));
  EXPECT_EQ(knot_velocity_neighbourhood(central, 9, 10), Range(8, 9));
  EXPECT_EQ(knot_velocity_neighbourhood(bessel, 0, 10), Range(0, 2));
  EXPECT_EQ(knot_velocity_neighbourhood(bessel, 9, 10), Range(7, 9));
  EXPECT_EQ(knot_velocity_neighbourhood(bessel, 0, 2), Range(0, 1));
  EXPECT_EQ(knot_velocity_neighbourhood(fit, 1, 10), Range(0, 4));
  EXPECT_EQ(knot_velocity_neighbourhood(fit, 5, 10), Range(3, 7));
  EXPECT_EQ(knot_velocity_neighbourhood(fit, 8, 10), Range(5, 9));
  EXPECT_EQ(knot_velocity_neighbourhood(fit, 8, std::numeric_limits<std::size_t>::max()), Range(6, 10));
  EXPECT_THROW(validate(KnotVelocityOptions{KnotVelocityEstimator::LocalQuadraticFit, 0}), std::invalid_argument);
  EXPECT_THROW(validate(KnotVelocityOptions{KnotVelocityEstimator::LocalQuadraticFit, kMaxFitHalfWidth + 1}),
               std::invalid_argument);
}

}  // namespace
}  // namespace posefair::geometric_splines
