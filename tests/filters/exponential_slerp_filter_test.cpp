#include "posefair/core/exponential_slerp_filter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "filter_test_support.hpp"

namespace posefair {
namespace {

using testing::angle_about;
using testing::random_unit_quaternion;

std::vector<Quat> slerp_input_stream(std::uint64_t seed, int n, double dt) {
  return testing::noisy_rotation_stream(
      seed, n, dt, {Vec3(2.0, 1.5, 2.8), Vec3(1.1, 0.7, 0.3), /*phase=*/0.5, /*noise=*/0.05});
}

TEST(ExponentialSlerp, StepResponseAfterNStepsIsGeometric) {
  const Vec3 axis = Vec3(1.0, -2.0, 2.0) / 3.0;
  const Quat base(0.5, -0.5, 0.5, 0.5);
  for (double alpha : {0.05, 0.2, 0.7}) {
    for (double step : {0.3, 2.0, 3.0}) {  // physical angles, up to near pi
      auto f = ExponentialSlerpFilter::with_alpha(alpha);
      f.filter(base, 0.0);
      const Quat target = base * so3::from_rotation_vector(step * axis);
      for (int n = 1; n <= 60; ++n) {
        const Quat y = f.filter(target, 0.01 * n);
        const Quat rel = base.conjugate() * y;
        const double expected = (1.0 - std::pow(1.0 - alpha, n)) * step;
        ASSERT_NEAR(angle_about(rel, axis), expected, 1e-12) << "alpha " << alpha << " step " << step << " n " << n;
        ASSERT_LE((rel.vec() - rel.vec().dot(axis) * axis).norm(), 1e-13);
      }
    }
  }
}

TEST(ExponentialSlerp, TimeConstantStepResponseFollowsIrregularSampling) {
  // With a time constant the remaining fraction after each sample is (1 - alpha(tau, dt_k)).
  const Vec3 axis = Vec3(0.0, 0.0, 1.0);
  const double tau = 0.08, step = 1.5;
  std::mt19937_64 rng(71);
  std::uniform_real_distribution<double> dts(0.002, 0.03);
  auto f = ExponentialSlerpFilter::with_time_constant(tau);
  f.filter(Quat::Identity(), 5.0);
  const Quat target = so3::from_rotation_vector(step * axis);
  double t = 5.0, remaining = 1.0;
  for (int n = 1; n <= 100; ++n) {
    const double t_new = t + dts(rng);
    const double dt = t_new - t;  // the spacing the filter sees
    t = t_new;
    const Quat y = f.filter(target, t);
    remaining *= 1.0 - smoothing_alpha_from_time_constant(tau, dt);
    ASSERT_NEAR(angle_about(y, axis), (1.0 - remaining) * step, 1e-11) << n;
  }
  EXPECT_LT(remaining, 1e-3);
}

TEST(ExponentialSlerp, TimeConstantEquivalentToFixedAlphaAtConstantRate) {
  for (double rate : {100.0, 200.0, 60.0}) {
    const double dt = 1.0 / rate, tau = 0.05;
    const double alpha = 1.0 / (1.0 + tau / dt);
    const std::vector<Quat> qs = slerp_input_stream(73, 1000, dt);
    auto timed = ExponentialSlerpFilter::with_time_constant(tau);
    auto fixed = ExponentialSlerpFilter::with_alpha(alpha);
    auto other = ExponentialSlerpFilter::with_alpha(0.5 * alpha);
    double max_other = 0.0;
    for (std::size_t k = 0; k < qs.size(); ++k) {
      const double t = 2.0 + k * dt;
      const Quat a = timed.filter(qs[k], t);
      const Quat b = fixed.filter(qs[k], t);
      ASSERT_LT(so3::dist(a, b), 1e-11) << "rate " << rate << " sample " << k;
      max_other = std::max(max_other, so3::dist(a, other.filter(qs[k], t)));
    }
    EXPECT_GT(max_other, 1e-3) << "the comparison must be able to fail";
  }
}

TEST(ExponentialSlerp, FirstSamplePassesThroughNormalisedAndAlphaOneIsPassThrough) {
  std::mt19937_64 rng(79);
  auto f = ExponentialSlerpFilter::with_alpha(1.0);
  EXPECT_FALSE(f.initialized());
  for (int k = 0; k < 50; ++k) {
    const Quat q = random_unit_quaternion(rng);
    const Quat y = f.filter(Quat(2.5 * q.coeffs()), 0.1 * k);
    if (k == 0) {
      EXPECT_LT((y.coeffs() - q.coeffs()).norm(), 1e-15);
    }
    EXPECT_LT(so3::dist(y, q), 1e-14) << k;
  }
  EXPECT_TRUE(f.initialized());
}

TEST(ExponentialSlerp, UnitNormContinuityAndHemisphereInvariance) {
  const double dt = 0.01;
  const std::vector<Quat> qs = slerp_input_stream(83, 4000, dt);
  std::mt19937_64 rng(89);
  std::bernoulli_distribution flip(0.5);
  std::uniform_real_distribution<double> scale(0.3, 4.0);
  auto plain = ExponentialSlerpFilter::with_time_constant(0.03);
  auto messy = ExponentialSlerpFilter::with_time_constant(0.03);
  Quat prev = Quat::Identity();
  for (std::size_t k = 0; k < qs.size(); ++k) {
    const Quat in(scale(rng) * (flip(rng) ? -1.0 : 1.0) * qs[k].coeffs());
    const Quat a = plain.filter(qs[k], k * dt);
    const Quat b = messy.filter(in, k * dt);
    ASSERT_NEAR(b.norm(), 1.0, 1e-14) << k;
    ASSERT_LT(so3::dist(a, b), 1e-12) << k;
    if (k > 0) {
      ASSERT_GT(b.dot(prev), 0.0) << "output jumped hemisphere at " << k;
    }
    prev = b;
  }
}

TEST(ExponentialSlerp, ConstantInputIsAFixedPoint) {
  std::mt19937_64 rng(97);
  const Quat q = random_unit_quaternion(rng);
  auto f = ExponentialSlerpFilter::with_alpha(0.3);
  for (int k = 0; k < 500; ++k) {
    const Quat y = f.filter(k % 2 ? Quat(-q.coeffs()) : q, 0.01 * k);
    ASSERT_LT(so3::dist(y, q), 1e-14) << k;
  }
}

TEST(ExponentialSlerp, RepeatedOrOlderTimestampReturnsPreviousOutputAndKeepsState) {
  const double dt = 0.01;
  const std::vector<Quat> qs = slerp_input_stream(101, 500, dt);
  std::mt19937_64 rng(103);
  for (bool timed : {false, true}) {
    auto make = [&] {
      return timed ? ExponentialSlerpFilter::with_time_constant(0.04) : ExponentialSlerpFilter::with_alpha(0.2);
    };
    auto clean = make(), dirty = make();
    for (std::size_t k = 0; k < qs.size(); ++k) {
      const double t = k * dt;
      const Quat y = dirty.filter(qs[k], t);
      ASSERT_EQ(y.coeffs(), clean.filter(qs[k], t).coeffs()) << k;
      if (k % 4 == 1) {
        const Quat wild = random_unit_quaternion(rng);
        ASSERT_EQ(dirty.filter(wild, t).coeffs(), y.coeffs()) << "repeated timestamp at " << k;
        ASSERT_EQ(dirty.filter(wild, t - 0.5).coeffs(), y.coeffs()) << "older timestamp at " << k;
        ASSERT_EQ(dirty.filter(wild, std::numeric_limits<double>::quiet_NaN()).coeffs(), y.coeffs()) << k;
      }
    }
  }
}

TEST(ExponentialSlerp, ResetForgetsHistory) {
  const double dt = 0.01;
  const std::vector<Quat> qs = slerp_input_stream(107, 300, dt);
  auto used = ExponentialSlerpFilter::with_time_constant(0.05);
  for (std::size_t k = 0; k < 100; ++k) used.filter(qs[299 - k], 50.0 + k * dt);
  used.reset();
  EXPECT_FALSE(used.initialized());
  auto fresh = ExponentialSlerpFilter::with_time_constant(0.05);
  for (std::size_t k = 0; k < qs.size(); ++k) {
    ASSERT_EQ(used.filter(qs[k], k * dt).coeffs(), fresh.filter(qs[k], k * dt).coeffs()) << k;
  }
}

TEST(ExponentialSlerp, RejectsInvalidParameters) {
  EXPECT_THROW(ExponentialSlerpFilter::with_alpha(0.0), std::invalid_argument);
  EXPECT_THROW(ExponentialSlerpFilter::with_alpha(1.5), std::invalid_argument);
  EXPECT_THROW(ExponentialSlerpFilter::with_alpha(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  EXPECT_THROW(ExponentialSlerpFilter::with_time_constant(-0.1), std::invalid_argument);
  EXPECT_THROW(ExponentialSlerpFilter::with_time_constant(std::numeric_limits<double>::infinity()),
               std::invalid_argument);
  EXPECT_TRUE(ExponentialSlerpFilter::with_alpha(0.25).has_fixed_alpha());
  EXPECT_FALSE(ExponentialSlerpFilter::with_time_constant(0.0).has_fixed_alpha());
  EXPECT_EQ(ExponentialSlerpFilter::with_time_constant(0.02).parameter(), 0.02);
}

}  // namespace
}  // namespace posefair
