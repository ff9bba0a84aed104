#include "posefair/core/pose_prediction.hpp"

#include <cmath>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

#include "filter_test_support.hpp"

namespace posefair {
namespace {

using testing::angle_about;
using testing::random_unit_quaternion;

// A rotation at constant body-frame angular velocity w (rad/s) from base.
Quat constant_rate(const Quat& base, const Vec3& w, double t) { return base * so3::from_rotation_vector(w * t); }

TEST(PosePrediction, DeadReckoningIsExactOnConstantAngularVelocityWithJitteredTimes) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> jitter(0.5, 1.5);
  const Quat base = random_unit_quaternion(rng);
  const Vec3 w(2.0, -1.0, 3.5);  // about 4.2 rad/s
  DeadReckoningPredictor p;
  double t = 0.0;
  for (int k = 0; k < 200; ++k) {
    p.push(constant_rate(base, w, t), t);
    if (k > 0) {
      ASSERT_LT((p.velocity() - w).norm(), 1e-9) << k;
      for (double h : {0.01, 0.02, 0.03})
        ASSERT_LT(so3::rotation_angle(p.predict(h), constant_rate(base, w, t + h)), 1e-11) << k << " h " << h;
    }
    t += 0.01 * jitter(rng);
  }
}

TEST(PosePrediction, FirstSampleIsHeldAndRepeatedTimesAreDropped) {
  const Quat q0 = so3::from_rotation_vector(Vec3(0.3, 0.0, 0.0));
  const Quat q1 = so3::from_rotation_vector(Vec3(0.4, 0.0, 0.0));
  DeadReckoningPredictor dr;
  SlerpExtrapolationPredictor sl(0.01);
  dr.push(q0, 1.0);
  sl.push(q0, 1.0);
  EXPECT_LT(so3::rotation_angle(dr.predict(0.02), q0), 1e-15);
  EXPECT_LT(so3::rotation_angle(sl.predict(0.02), q0), 1e-15);
  dr.push(q1, 1.0);  // same time: dropped
  sl.push(q1, 1.0);
  EXPECT_LT(so3::rotation_angle(dr.predict(0.02), q0), 1e-15);
  EXPECT_LT(so3::rotation_angle(sl.predict(0.02), q0), 1e-15);
  dr.push(q1, 1.01);  // 0.1 rad in 10 ms: 10 rad/s about x
  sl.push(q1, 1.01);
  const Vec3 x = Vec3::UnitX();
  EXPECT_NEAR(angle_about(dr.predict(0.02), x), 0.6, 1e-12);
  EXPECT_NEAR(angle_about(sl.predict(0.02), x), 0.6, 1e-12);
}

TEST(PosePrediction, SlerpExtrapolationEqualsDeadReckoningOnEvenSpacingButNotAcrossADropout) {
  const auto stream = testing::noisy_rotation_stream(
      9, 300, 0.005, {Vec3(2.0, 1.5, 2.8), Vec3(1.1, 0.7, 0.3), /*phase=*/0.5, /*noise=*/0.02});
  DeadReckoningPredictor dr;
  SlerpExtrapolationPredictor sl(0.005);
  for (std::size_t k = 0; k < stream.size(); ++k) {
    dr.push(stream[k], 0.005 * static_cast<double>(k));
    sl.push(stream[k], 0.005 * static_cast<double>(k));
    for (double h : {0.01, 0.03}) ASSERT_LT(so3::rotation_angle(dr.predict(h), sl.predict(h)), 1e-10) << k;
  }
  // A dropout: the step spans two periods. Dead reckoning divides by the real interval, the
  // frame-based slerp by the nominal one, so it extrapolates twice the rate.
  const Quat a = so3::from_rotation_vector(Vec3(0.0, 0.1, 0.0));
  const Quat b = so3::from_rotation_vector(Vec3(0.0, 0.2, 0.0));
  DeadReckoningPredictor dr2;
  SlerpExtrapolationPredictor sl2(0.005);
  dr2.push(a, 0.0);
  sl2.push(a, 0.0);
  dr2.push(b, 0.010);
  sl2.push(b, 0.010);
  const Vec3 y = Vec3::UnitY();
  EXPECT_NEAR(angle_about(dr2.predict(0.01), y), 0.3, 1e-12);
  EXPECT_NEAR(angle_about(sl2.predict(0.01), y), 0.4, 1e-12);
  EXPECT_THROW(SlerpExtrapolationPredictor(0.0), std::invalid_argument);
}

TEST(PosePrediction, OneEuroDeadReckoningSettlesAtItsDocumentedBias) {
  // β = 0: constant smoothing factor α per sample; after settling, the prediction misses the
  // truth by ω (1 − α)/α (h − Δ) along the axis of motion.
  const double dt = 0.01, mincutoff = 4.0, omega = 0.2;  // 1.2 rad in all: no wrap
  const double alpha = smoothing_alpha_from_cutoff(mincutoff, dt);
  const Vec3 z = Vec3::UnitZ();
  OneEuroDeadReckoningPredictor p(mincutoff, 0.0, 1.0);
  double t = 0.0;
  for (int k = 0; k < 600; ++k, t += dt) p.push(so3::from_rotation_vector(omega * t * z), t);
  t -= dt;
  for (double h : {0.01, 0.02, 0.03}) {
    const double predicted = angle_about(p.predict(h), z);
    const double expected_miss = omega * (1.0 - alpha) / alpha * (h - dt);
    EXPECT_NEAR(predicted - omega * (t + h), expected_miss, 1e-9) << "h " << h;
  }
  EXPECT_NEAR(p.filter().derivative().z(), omega / alpha, 1e-9);
}

}  // namespace
}  // namespace posefair
