// pose_interpolation = "matrix-lerp" (rigid_pose_lerp.hpp and its use in gap_bridge.hpp and
// fixed_rate_resampler.hpp): exact on a screw motion where the separate interpolation is not,
// slerp for a pure rotation, and a step of pi/2 or more interpolated separately and counted.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "posefair/core/fixed_rate_resampler.hpp"
#include "posefair/core/gap_bridge.hpp"
#include "posefair/core/rigid_pose_lerp.hpp"

namespace posefair {
namespace {

// A screw motion: turning at 2 rad/s about the axis u through c while advancing 0.3 m/s along
// it (a point on a helix). Lerp of the 4x4 transform follows it exactly.
const Vec3 kAxis = Vec3(1.0, 2.0, 0.5).normalized();
const Vec3 kCentre(0.4, -0.2, 1.0);
const Vec3 kBodyStart(1.2, 0.3, -0.5);
const Quat kStart = so3::from_rotation_vector(Vec3(0.3, -1.0, 2.0));
Quat screw_q(double t) { return so3::from_rotation_vector(2.0 * t * kAxis) * kStart; }
Vec3 screw_p(double t) {
  return kCentre + so3::from_rotation_vector(2.0 * t * kAxis) * (kBodyStart - kCentre) + 0.3 * t * kAxis;
}

TEST(RigidPoseLerp, ReproducesAScrewMotionBetweenSamplesWhereSlerpAndALineDoNot) {
  RigidPoseLerp lerp;
  const double t0 = 0.1, t1 = 0.35;  // 0.5 rad apart
  ASSERT_TRUE(lerp.prepare(screw_q(t0), screw_p(t0), screw_q(t1), screw_p(t1)));
  double worst_separate = 0.0;
  for (double f : {0.0, 0.1, 0.25, 0.5, 0.8, 1.0}) {
    const double t = t0 + f * (t1 - t0);
    Quat q;
    Vec3 p;
    lerp.at(f, q, p);
    EXPECT_LT(so3::rotation_angle(q, screw_q(t)), 1e-9) << f;
    EXPECT_LT((p - screw_p(t)).norm(), 1e-9) << f;
    EXPECT_NEAR(q.norm(), 1.0, 1e-12);
    const Vec3 line = screw_p(t0) + f * (screw_p(t1) - screw_p(t0));
    worst_separate = std::max(worst_separate, (line - screw_p(t)).norm());
  }
  EXPECT_GT(worst_separate, 1e-2) << "the straight line cuts the helix's chord";
  EXPECT_EQ(lerp.fallbacks(), 0u);
}

TEST(RigidPoseLerp, APureRotationIsSlerp) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  RigidPoseLerp lerp;
  double worst_small = 0.0, worst = 0.0;  // steps up to 30 degrees (3000 deg/s at 100 Hz); all
  for (int i = 0; i < 200; ++i) {
    const Quat a = Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
    const double angle = 1.56 * static_cast<double>(i + 1) / 200.0;  // up to 89.4 degrees
    const Quat b = so3::from_rotation_vector(angle * Vec3(g(rng), g(rng), g(rng)).normalized()) * a;
    ASSERT_TRUE(lerp.prepare(a, Vec3::Zero(), b, Vec3::Zero()));
    for (double f : {0.0, 0.3, 0.5, 0.9, 1.0}) {
      Quat q;
      Vec3 p;
      lerp.at(f, q, p);
      const double e = so3::rotation_angle(q, so3::slerp(f, a, b));
      worst = std::max(worst, e);
      if (angle <= 30.0 * std::numbers::pi / 180.0) worst_small = std::max(worst_small, e);
      EXPECT_LT(p.norm(), 1e-12);
      EXPECT_GE(q.dot(a), 0.0) << "in a's hemisphere";
    }
  }
  EXPECT_LT(worst_small, 1e-12);
  EXPECT_LT(worst, 3e-12);  // measured 1.2e-12 near 70 degrees: the logarithm's iteration error
}

TEST(RigidPoseLerp, AStepOfAQuarterTurnOrMoreIsInterpolatedSeparatelyAndCounted) {
  RigidPoseLerp lerp;
  const Quat a = so3::from_rotation_vector(Vec3(0.2, 0.1, 0.0));
  const Vec3 pa(1.0, 2.0, 3.0), pb(2.0, 0.0, 3.0);
  for (double degrees : {90.0, 120.0, 179.0}) {
    const Quat b = so3::from_rotation_vector(degrees * std::numbers::pi / 180.0 * Vec3(0.0, 0.6, 0.8)) * a;
    EXPECT_FALSE(lerp.prepare(a, pa, b, pb)) << degrees;
    EXPECT_FALSE(lerp.matrix());
    for (double f : {0.0, 0.5, 1.0}) {
      Quat q;
      Vec3 p;
      lerp.at(f, q, p);
      EXPECT_LT(so3::rotation_angle(q, so3::slerp(f, a, b)), 1e-12);
      EXPECT_LT((p - (pa + f * (pb - pa))).norm(), 1e-12);
    }
  }
  EXPECT_EQ(lerp.fallbacks(), 3u);
  // Just under a quarter turn: lerp.
  const Quat b = so3::from_rotation_vector(89.9 * std::numbers::pi / 180.0 * Vec3(0.0, 0.6, 0.8)) * a;
  EXPECT_TRUE(lerp.prepare(a, pa, b, pb));
  EXPECT_EQ(lerp.fallbacks(), 3u);
  // Not finite: separately (and the caller's gate sees the nan).
  EXPECT_FALSE(lerp.prepare(a, Vec3(std::nan(""), 0.0, 0.0), b, pb));
}

FairedPose screw_pose(double t) {
  FairedPose p;
  p.stream_id = 2;
  p.time = t;
  p.orientation = screw_q(t);
  p.position = screw_p(t);
  p.flags = kHasPosition;
  return p;
}

TEST(FixedRateResamplerMatrixLerp, A100HzScrewComesOutExactlyOnThe250HzGridOneIntervalLate) {
  FixedRateResamplerOptions o;
  o.rate_hz = 250.0;
  o.interpolation = PoseInterpolation::MatrixLerp;
  FixedRateResampler r(o);
  EXPECT_EQ(r.delay_intervals(), 1u);
  std::vector<FairedPose> out(r.max_outputs());
  std::size_t grid = 0;
  double worst_q = 0.0, worst_p = 0.0, worst_delay = 0.0;
  double last_t = -1.0;
  for (int i = 0; i < 100; ++i) {
    const double t = 0.0013 + 0.01 * i;
    const std::size_t n = r.push(screw_pose(t), out);
    for (std::size_t j = 0; j < n; ++j) {
      const FairedPose& g = out[j];
      EXPECT_NEAR(g.time * 250.0, std::round(g.time * 250.0), 1e-9) << "on the grid";
      EXPECT_GT(g.time, last_t);
      last_t = g.time;
      EXPECT_EQ(g.flags, kHasPosition);
      worst_q = std::max(worst_q, so3::rotation_angle(g.orientation, screw_q(g.time)));
      worst_p = std::max(worst_p, (g.position - screw_p(g.time)).norm());
      worst_delay = std::max(worst_delay, t - g.time);
    }
    grid += n;
  }
  EXPECT_EQ(grid, 247u) << "every grid time from the first faired pose to the last";
  EXPECT_LT(worst_q, 1e-9);
  EXPECT_LT(worst_p, 1e-9);
  EXPECT_LE(worst_delay, 0.01 + 1e-12);
  EXPECT_EQ(r.lerp_fallbacks(), 0u);

  // The spline on rotation and position separately (order 1, the C^1 curve) does not follow
  // the helix exactly.
  o.interpolation = PoseInterpolation::Spline;
  o.spline.order = 1;
  FixedRateResampler s(o);
  double spline_worst_p = 0.0;
  for (int i = 0; i < 100; ++i) {
    const std::size_t n = s.push(screw_pose(0.0013 + 0.01 * i), out);
    for (std::size_t j = 0; j < n; ++j) spline_worst_p = std::max(spline_worst_p, (out[j].position - screw_p(out[j].time)).norm());
  }
  EXPECT_GT(spline_worst_p, 1e-7);
}

TEST(FixedRateResamplerMatrixLerp, AQuarterTurnBetweenFairedPosesIsSeparateAndCounted) {
  FixedRateResamplerOptions o;
  o.rate_hz = 250.0;
  o.interpolation = PoseInterpolation::MatrixLerp;
  FixedRateResampler r(o);
  std::vector<FairedPose> out(r.max_outputs());
  FairedPose a = screw_pose(0.0), b = screw_pose(0.01);
  b.orientation = so3::from_rotation_vector(Vec3(0.0, 0.0, 2.0)) * a.orientation;  // 115 degrees
  b.flags = kHasPosition | kBridged;
  EXPECT_EQ(r.push(a, out), 0u);
  ASSERT_EQ(r.push(b, out), 3u);  // 0, 4, 8 ms
  for (std::size_t j = 0; j < 3; ++j) {
    const double f = out[j].time / 0.01;
    EXPECT_LT(so3::rotation_angle(out[j].orientation, so3::slerp(f, a.orientation, b.orientation)), 1e-12);
    EXPECT_LT((out[j].position - (a.position + f * (b.position - a.position))).norm(), 1e-12);
    EXPECT_EQ(out[j].flags, kHasPosition | kBridged);
  }
  EXPECT_EQ(r.lerp_fallbacks(), 1u);
}

TEST(FixedRateResamplerMatrixLerp, WithoutPositionItIsSlerpAndALongStepRestarts) {
  FixedRateResamplerOptions o;
  o.rate_hz = 100.0;
  o.max_step = 0.05;
  o.interpolation = PoseInterpolation::MatrixLerp;
  FixedRateResampler r(o);
  std::vector<FairedPose> out(r.max_outputs());
  FairedPose prev = screw_pose(0.0);
  prev.flags = 0;
  r.push(prev, out);
  std::size_t grid = 0;
  for (double t : {0.025, 0.05, 0.2, 0.215}) {  // 0.05 -> 0.2 is longer than max_step
    FairedPose p = screw_pose(t);
    p.flags = 0;
    const std::size_t n = r.push(p, out);
    for (std::size_t j = 0; j < n; ++j) {
      EXPECT_EQ(out[j].flags, 0u);
      EXPECT_EQ(out[j].position, Vec3::Zero());
      EXPECT_FALSE(out[j].time > 0.05 && out[j].time < 0.2) << "no pose across the restart";
      const double f = (out[j].time - prev.time) / (p.time - prev.time);
      EXPECT_LT(so3::rotation_angle(out[j].orientation, so3::slerp(f, prev.orientation, p.orientation)), 1e-12);
    }
    grid += n;
    prev = p;
  }
  EXPECT_EQ(grid, 6u + 2u);  // 0..50 ms, then 200 and 210 ms
  EXPECT_EQ(r.restarts(), 1u);
}

Sample screw_sample(double t, std::uint64_t seq) {
  Sample s;
  s.stream_id = 2;
  s.sequence = seq;
  s.time = t;
  s.receive_time = t;
  s.orientation = screw_q(t);
  s.position = screw_p(t);
  s.flags = kHasPosition;
  return s;
}

TEST(GapBridgeMatrixLerp, FillsAGapAtOnceWithTheScrewMotion) {
  GapBridgeOptions o;
  o.interpolation = PoseInterpolation::MatrixLerp;
  GapBridge bridge(o);
  std::vector<Sample> out(bridge.max_outputs());
  for (int i = 0; i <= 50; ++i) ASSERT_EQ(bridge.push(screw_sample(0.01 * i, i), out), 1u);
  // Samples 51..56 lost: filled as soon as 57 arrives (nothing held).
  const std::size_t n = bridge.push(screw_sample(0.57, 57), out);
  ASSERT_EQ(n, 7u);
  for (std::size_t j = 0; j < 6; ++j) {
    const Sample& b = out[j];
    EXPECT_NEAR(b.time, 0.51 + 0.01 * static_cast<double>(j), 1e-12);
    EXPECT_EQ(b.flags, kBridged | kHasPosition);
    EXPECT_LT(so3::rotation_angle(b.orientation, screw_q(b.time)), 1e-9);
    EXPECT_LT((b.position - screw_p(b.time)).norm(), 1e-9);
  }
  EXPECT_EQ(out[6].sequence, 57u);
  EXPECT_EQ(bridge.push(screw_sample(0.58, 58), out), 1u);
  EXPECT_EQ(bridge.flush(out), 0u);
  EXPECT_EQ(bridge.counters().gaps, 1u);
  EXPECT_EQ(bridge.counters().samples, 6u);
  EXPECT_EQ(bridge.counters().lerp_fallbacks, 0u);

  // A gap across which the stream turned 120 degrees: bridged separately, counted.
  for (int i = 59; i <= 70; ++i) bridge.push(screw_sample(0.01 * i, i), out);
  Sample far = screw_sample(0.74, 74);
  far.orientation = so3::from_rotation_vector(Vec3(2.1, 0.0, 0.0)) * screw_q(0.70);
  ASSERT_EQ(bridge.push(far, out), 4u);
  for (std::size_t j = 0; j < 3; ++j) EXPECT_NEAR(out[j].orientation.norm(), 1.0, 1e-12);
  EXPECT_EQ(bridge.counters().gaps, 2u);
  EXPECT_EQ(bridge.counters().lerp_fallbacks, 1u);
}

}  // namespace
}  // namespace posefair
