// The three-step algorithm in R^n: Theorem 3.1's conditions and C^k continuity by the coded
// analytic derivatives, Remark 3.3's cubic, the (k+1)-th derivative jump formulas after
// Remark 3.4, Corollary 3.1's uneven conditions, non-uniform knots (ERRATA item 4).
#include <array>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "geometric_spline_test_support.hpp"
#include "posefair/core/euclidean_geometric_spline.hpp"

namespace posefair::geometric_splines {
namespace {

using V = Vector<Eigen::Dynamic>;

V random_vector(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> d(-2.0, 2.0);
  V v(n);
  for (int i = 0; i < n; ++i) v[i] = d(rng);
  return v;
}

// Non-uniform times, random values and velocities (k_i = 1).
std::vector<EuclideanKnot<Eigen::Dynamic>> random_knots(std::mt19937& rng, int count, int n) {
  std::uniform_real_distribution<double> step(0.2, 2.5);
  std::vector<EuclideanKnot<Eigen::Dynamic>> knots(count);
  double t = -1.0;
  for (auto& k : knots) {
    k.time = t;
    t += step(rng);
    k.derivative = {random_vector(rng, n), random_vector(rng, n)};
  }
  return knots;
}

TEST(EuclideanGeometricSpline, OrderOneIsTheCubicOfRemark33) {
  std::mt19937 rng(1);
  const SmoothingFunction phi(1);
  for (int trial = 0; trial < 10; ++trial) {
    const V p0 = random_vector(rng, 3), v0 = random_vector(rng, 3), p1 = random_vector(rng, 3),
            v1 = random_vector(rng, 3);
    const std::array<V, 2> left{p0, v0}, right{p1, v1};
    for (double u = 0.0; u <= 1.0; u += 0.05) {
      const V cubic = p0 + v0 * u + (3 * p1 - 3 * p0 - 2 * v0 - v1) * u * u + (2 * p0 + v0 - 2 * p1 + v1) * u * u * u;
      EXPECT_LT((euclidean_segment<Eigen::Dynamic>(phi, left, right, 1.0, u) - cubic).norm(), 1e-13);
    }
  }
}

TEST(EuclideanGeometricSpline, Theorem31ConditionsAndCkAtEveryKnotOnNonUniformKnots) {
  std::mt19937 rng(2);
  for (int k = 1; k <= 5; ++k) {
    const auto knots = random_knots(rng, 6, 4);
    const EuclideanGeometricSpline<Eigen::Dynamic> s(knots, k);
    for (std::size_t i = 0; i < knots.size(); ++i) {
      for (int j = 0; j <= k; ++j) {
        const V expected = j < 2 ? knots[i].derivative[j] : V::Zero(4);
        const double tol = 1e-9 * (1 + expected.norm());
        // From the segment on the right and the one on the left of the knot (C^k).
        if (i + 1 < knots.size()) {
          EXPECT_LT((s.evaluate_segment(i, knots[i].time, j) - expected).norm(), tol) << k << j;
        }
        if (i > 0) {
          EXPECT_LT((s.evaluate_segment(i - 1, knots[i].time, j) - expected).norm(), tol) << k << j;
        }
      }
    }
    // Inside a segment the coded derivative agrees with finite differences of the values.
    const double t = 0.37 * knots[1].time + 0.63 * knots[2].time;
    for (int j = 1; j <= 3; ++j) {
      const V fd = testing::derivative([&](double x) { return s.evaluate_segment(1, x, 0); }, t, j, 0.02);
      EXPECT_LT((s.evaluate_segment(1, t, j) - fd).norm(), 1e-7 * (1 + fd.norm())) << k << " " << j;
    }
  }
}

TEST(EuclideanGeometricSpline, NotCkPlusOneAndTheJumpFormulasAfterRemark34) {
  // Unit spacing, as in the paper. k = 1: s''_i(1) = 2(x_i - p_{i+1}) + 4(v_{i+1} - p_{i+1} + p_i) and
  // s''_{i+1}(0) = 2(x_{i+2} - p_{i+1}) + 4(p_{i+2} - p_{i+1} - v_{i+1}); k > 1:
  // s^(k+1)_i(1) = 2(k+1) phi^(k)(1) (v_{i+1} - p_{i+1} + p_i), s^(k+1)_{i+1}(0) = 2(k+1) phi^(k)(0) (p_{i+2} - p_{i+1} - v_{i+1}).
  std::mt19937 rng(3);
  for (int k = 1; k <= 4; ++k) {
    auto knots = random_knots(rng, 3, 3);
    for (int i = 0; i < 3; ++i) knots[i].time = i;
    const EuclideanGeometricSpline<Eigen::Dynamic> s(knots, k);
    const SmoothingFunction phi(k);
    const V &p0 = knots[0].derivative[0], &p1 = knots[1].derivative[0], &p2 = knots[2].derivative[0];
    const V &v0 = knots[0].derivative[1], &v1 = knots[1].derivative[1], &v2 = knots[2].derivative[1];
    const V left = s.evaluate_segment(0, 1.0, k + 1), right = s.evaluate_segment(1, 1.0, k + 1);
    V expected_left, expected_right;
    if (k == 1) {
      expected_left = 2 * (p0 + v0 - p1) + 4 * (v1 - p1 + p0);
      expected_right = 2 * (p2 - v2 - p1) + 4 * (p2 - p1 - v1);
    } else {
      expected_left = 2 * (k + 1) * phi.derivative(1.0, k) * (v1 - p1 + p0);
      expected_right = 2 * (k + 1) * phi.derivative(0.0, k) * (p2 - p1 - v1);
    }
    EXPECT_LT((left - expected_left).norm(), 1e-9 * expected_left.norm()) << k;
    EXPECT_LT((right - expected_right).norm(), 1e-9 * expected_right.norm()) << k;
    EXPECT_GT((left - right).norm(), 1e-3) << k;  // generic data: not C^{k+1}
  }
}

TEST(EuclideanGeometricSpline, UnevenConditionsOfCorollary31) {
  std::mt19937 rng(4);
  const int k = 4;
  const std::array<int, 5> prescribed{1, 3, 2, 4, 1};
  std::vector<EuclideanKnot<Eigen::Dynamic>> knots(prescribed.size());
  double t = 0.0;
  for (std::size_t i = 0; i < knots.size(); ++i) {
    knots[i].time = t;
    t += 0.3 + 0.4 * i;
    for (int j = 0; j <= prescribed[i]; ++j) knots[i].derivative.push_back(random_vector(rng, 2));
  }
  const EuclideanGeometricSpline<Eigen::Dynamic> s(knots, k);
  for (std::size_t i = 0; i < knots.size(); ++i)
    for (int j = 0; j <= k; ++j) {
      const V expected = j <= prescribed[i] ? knots[i].derivative[j] : V::Zero(2);
      const double tol = 1e-9 * (1 + expected.norm());
      if (i + 1 < knots.size()) {
        EXPECT_LT((s.evaluate_segment(i, knots[i].time, j) - expected).norm(), tol) << i << j;
      }
      if (i > 0) {
        EXPECT_LT((s.evaluate_segment(i - 1, knots[i].time, j) - expected).norm(), tol) << i << j;
      }
    }
}

TEST(EuclideanGeometricSpline, VelocitiesArePerSecondOnAnySpacing) {
  // ERRATA 4: a straight line at 3 units/s with knots 0.01 s and 2 s apart is reproduced exactly.
  const V dir = (V(3) << 1.0, -2.0, 2.0).finished() / 3.0;
  std::vector<EuclideanKnot<Eigen::Dynamic>> knots;
  for (double t : {0.0, 0.01, 2.01, 2.5}) knots.push_back({t, {3.0 * t * dir, 3.0 * dir}});
  for (int k = 1; k <= 3; ++k) {
    const EuclideanGeometricSpline<Eigen::Dynamic> s(knots, k);
    for (double t = 0.0; t <= 2.5; t += 0.01) {
      EXPECT_LT((s.evaluate(t) - 3.0 * t * dir).norm(), 1e-12) << t;
      EXPECT_LT((s.evaluate(t, 1) - 3.0 * dir).norm(), 1e-10) << t;
    }
  }
}

TEST(EuclideanGeometricSpline, FixedSizeMatchesDynamic) {
  std::mt19937 rng(5);
  auto dyn = random_knots(rng, 4, 3);
  std::vector<EuclideanKnot<3>> fixed;
  for (const auto& k : dyn) fixed.push_back({k.time, {k.derivative[0], k.derivative[1]}});
  const EuclideanGeometricSpline<Eigen::Dynamic> a(dyn, 2);
  const EuclideanGeometricSpline<3> b(fixed, 2);
  for (double t = a.start_time(); t <= a.end_time(); t += 0.05) EXPECT_LT((a.evaluate(t) - b.evaluate(t)).norm(), 1e-15);
}

TEST(EuclideanGeometricSpline, RejectsBadKnots) {
  std::mt19937 rng(6);
  auto knots = random_knots(rng, 3, 2);
  EXPECT_THROW((EuclideanGeometricSpline<Eigen::Dynamic>({knots[0]}, 2)), std::invalid_argument);
  auto equal_times = knots;
  equal_times[2].time = equal_times[1].time;
  EXPECT_THROW((EuclideanGeometricSpline<Eigen::Dynamic>(equal_times, 2)), std::invalid_argument);
  auto too_many = knots;
  too_many[1].derivative.resize(4, V::Zero(2));  // k_1 = 3 > k = 2
  EXPECT_THROW((EuclideanGeometricSpline<Eigen::Dynamic>(too_many, 2)), std::invalid_argument);
  const EuclideanGeometricSpline<Eigen::Dynamic> s(knots, 2);
  EXPECT_THROW(s.evaluate(s.end_time() + 1e-9), std::out_of_range);
}

}  // namespace
}  // namespace posefair::geometric_splines
