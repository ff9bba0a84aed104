#include "posefair/core/quality_metrics.hpp"

#include <gtest/gtest.h>

#include "posefair/core/synthetic_motion.hpp"
#include "test_sequences.hpp"

namespace posefair {
namespace {

TEST(QualityMetrics, RotationErrorIsThePhysicalAngle) {
  const std::vector<Quat> truth(10, Quat::Identity());
  std::vector<Quat> out(10, so3::from_rotation_vector(Vec3(0.0, 0.0, 0.1)));
  out[3] = so3::from_rotation_vector(Vec3(0.3, 0.0, 0.0));
  const ErrorStats e = rotation_error(out, truth);
  EXPECT_NEAR(e.max, 0.3, 1e-12);
  EXPECT_NEAR(e.rms, std::sqrt((9 * 0.01 + 0.09) / 10.0), 1e-12);
  const std::vector<char> use{1, 1, 1, 0, 1, 1, 1, 1, 1, 1};
  EXPECT_NEAR(rotation_error(out, truth, use).max, 0.1, 1e-12);
}

TEST(QualityMetrics, JitterIsZeroForConstantRateAndTheAccelerationOtherwise) {
  const double dt = 0.01;
  const auto constant = testing::sequence_with_linear_w1(50, Quat::Identity(), Vec3(0, 0, 0.02), Vec3::Zero());
  EXPECT_LT(jitter(constant, dt), 1e-9);
  // Half-angle increments growing by 0.001 per step: physical acceleration 2·0.001/dt².
  const auto accel = testing::sequence_with_linear_w1(50, Quat::Identity(), Vec3(0, 0, 0.02), Vec3(0, 0, 0.001));
  EXPECT_NEAR(jitter(accel, dt), 2 * 0.001 / (dt * dt), 1e-6);
}

TEST(QualityMetrics, LagToTruthFindsAKnownDelay) {
  SyntheticMotionSpec spec;
  spec.samples = 1000;
  spec.with_position = false;
  spec.cycles = 5;
  const auto m = make_synthetic_motion(spec);
  const double dt = 0.01;
  std::vector<Quat> delayed(m.truth.orientation.size());
  for (std::size_t i = 0; i < delayed.size(); ++i) delayed[i] = m.truth.orientation[i >= 4 ? i - 4 : 0];
  EXPECT_NEAR(lag_to_truth(delayed, m.truth.orientation, dt, 10), 0.04, 0.002);
  std::vector<Quat> leading(m.truth.orientation.size());
  for (std::size_t i = 0; i < leading.size(); ++i) leading[i] = m.truth.orientation[std::min(i + 2, leading.size() - 1)];
  EXPECT_NEAR(lag_to_truth(leading, m.truth.orientation, dt, 10), -0.02, 0.002);
}

TEST(QualityMetrics, BodyRatesAndGyroShift) {
  // Constant body rate ω = (0, 0, 2) rad/s sampled at 100 Hz: every rate equals ω.
  const double dt = 0.01;
  const auto q = testing::sequence_with_linear_w1(200, Quat::Identity(), Vec3(0, 0, 0.5 * 2.0 * dt), Vec3::Zero());
  std::vector<double> t(q.size());
  for (std::size_t i = 0; i < t.size(); ++i) t[i] = dt * static_cast<double>(i);
  const auto w = body_rates(q, t);
  for (const Vec3& v : w) EXPECT_LT((v - Vec3(0, 0, 2)).norm(), 1e-9);
  // A gyro reading a sine rate late by 7 ms: the best shift is +7 ms.
  std::vector<Quat> s{Quat::Identity()};
  std::vector<Vec3> gyro;
  auto rate = [](double time) { return Vec3(0, 0, std::sin(2 * M_PI * 1.3 * time)); };
  for (std::size_t i = 0; i + 1 < t.size(); ++i) {
    const double mid = 0.5 * (t[i] + t[i + 1]);
    s.push_back((s.back() * so3::exp(0.5 * dt * rate(mid))).normalized());
  }
  for (double ti : t) gyro.push_back(rate(ti - 0.007));
  const std::vector<char> use(t.size(), 1);
  const ShiftFit fit = best_rate_shift(body_rates(s, t), t, gyro, use, -0.02, 0.02, 0.0025);
  EXPECT_NEAR(fit.shift, 0.007, 0.0005);
  EXPECT_LT(fit.error, 0.01);
  EXPECT_GT(rate_error(body_rates(s, t), t, gyro, 0.0, use), 10 * fit.error);
}

TEST(QualityMetrics, AlignFramesRecoversWorldAndBodyRotations) {
  SyntheticMotionSpec spec;
  spec.samples = 300;
  spec.with_position = false;
  const auto m = make_synthetic_motion(spec);
  const Quat world = so3::exp(Vec3(0.3, -0.5, 0.2));
  const Quat body = so3::exp(Vec3(-0.1, 0.2, 0.4));
  std::vector<Quat> truth;
  for (const Quat& q : m.truth.orientation) truth.push_back(world * q * body);
  const FrameAlignment a = align_frames(m.truth.orientation, truth, true);
  EXPECT_LT(so3::dist(a.world, world), 1e-6);
  EXPECT_LT(so3::dist(a.body, body), 1e-6);
}

TEST(QualityMetrics, OrientationAtInterpolatesAndClamps) {
  PoseSequence s;
  s.time = {0.0, 1.0, 3.0};
  s.orientation = {Quat::Identity(), so3::exp(Vec3(0, 0, 0.2)), so3::exp(Vec3(0, 0, 0.6))};
  EXPECT_LT(so3::dist(orientation_at(s, 0.5), so3::exp(Vec3(0, 0, 0.1))), 1e-12);
  EXPECT_LT(so3::dist(orientation_at(s, 2.0), so3::exp(Vec3(0, 0, 0.4))), 1e-12);
  EXPECT_LT(so3::dist(orientation_at(s, -1.0), Quat::Identity()), 1e-15);
  EXPECT_LT(so3::dist(orientation_at(s, 9.0), s.orientation[2]), 1e-15);
}

}  // namespace
}  // namespace posefair
