// Pose splines (orientation on S^3 or SO(3), position in R^3) with estimated knot velocities,
// the batch resampler and the live window, on synthetic motion and on real recordings.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "posefair/core/pose_spline.hpp"
#include "posefair/core/pose_spline_window.hpp"

namespace posefair::geometric_splines {
namespace {

const std::vector<KnotVelocityEstimator> kEstimators{KnotVelocityEstimator::CentralDifference,
                                                     KnotVelocityEstimator::Bessel,
                                                     KnotVelocityEstimator::LocalQuadraticFit};

// Constant world angular velocity w and constant linear velocity: q(t) = exp(t w / 2) q0.
PoseSequence uniform_motion(const std::vector<double>& times, const Vec3& w, const Quat& q0) {
  PoseSequence s;
  for (double t : times) {
    s.time.push_back(t);
    s.orientation.push_back(so3::from_rotation_vector(t * w) * q0);
    s.position.push_back(Vec3(1.0, 2.0, 3.0) + t * Vec3(0.5, -0.25, 2.0));
  }
  return s;
}

TEST(PoseSpline, ReproducesUniformMotionWithEveryEstimatorManifoldAndOrder) {
  const std::vector<double> times{0.0, 0.01, 0.03, 0.04, 0.07, 0.08, 0.1, 0.13, 0.14};
  const Vec3 w(1.0, -3.0, 2.0);
  const Quat q0 = so3::exp(Vec3(0.3, 0.1, -0.4));
  const PoseSequence motion = uniform_motion(times, w, q0);
  for (auto e : kEstimators)
    for (auto m : {OrientationManifold::Sphere, OrientationManifold::LieGroup})
      for (int k = 1; k <= 3; ++k) {
        PoseSplineOptions o;
        o.order = k;
        o.manifold = m;
        o.velocity.estimator = e;
        o.velocity.fit_half_width = 2;
        const PoseSpline s(motion, o);
        for (const PoseKnot& knot : s.knots()) {
          EXPECT_LT((knot.angular_velocity - w).norm(), 1e-10);
          EXPECT_LT((knot.velocity - Vec3(0.5, -0.25, 2.0)).norm(), 1e-10);
        }
        for (double t = 0.0; t <= 0.14; t += 0.0025) {
          const SplinePose p = s.evaluate(t);
          EXPECT_LT(so3::rotation_angle(p.orientation, so3::from_rotation_vector(t * w) * q0), 1e-11);
          EXPECT_LT((p.position - (Vec3(1.0, 2.0, 3.0) + t * Vec3(0.5, -0.25, 2.0))).norm(), 1e-12);
          EXPECT_NEAR(p.orientation.norm(), 1.0, 4e-15);
          EXPECT_LT((s.angular_velocity(t) - w).norm(), 1e-6);
        }
      }
}

TEST(PoseSpline, InterpolatesTheSamplesAndHandlesSignFlips) {
  std::vector<double> times;
  PoseSequence s;
  for (int i = 0; i < 20; ++i) {
    s.time.push_back(0.02 * i + 0.003 * (i % 3));
    Quat q = so3::exp(Vec3(std::sin(0.3 * i), 0.2 * i, std::cos(0.1 * i)));
    if (i % 2) q.coeffs() *= -1.0;  // the same rotation with the other sign
    s.orientation.push_back(q);
  }
  for (auto m : {OrientationManifold::Sphere, OrientationManifold::LieGroup}) {
    PoseSplineOptions o;
    o.manifold = m;
    const PoseSpline spline(s, o);
    EXPECT_FALSE(spline.has_position());
    for (std::size_t i = 0; i < s.size(); ++i)
      EXPECT_LT(so3::rotation_angle(spline.evaluate(s.time[i]).orientation, s.orientation[i]), 1e-12);
    const PoseSequence r = resample(s, std::vector<double>{0.0, 0.1, 0.2, 0.3}, o);
    EXPECT_TRUE(r.position.empty());
    for (std::size_t i = 1; i < r.size(); ++i) EXPECT_GE(r.orientation[i].dot(r.orientation[i - 1]), 0.0);
  }
}

TEST(PoseSpline, RejectsBadInput) {
  PoseSequence s = uniform_motion({0.0, 0.1, 0.2}, Vec3(1, 0, 0), Quat::Identity());
  PoseSequence one = s;
  one.time.resize(1);
  one.orientation.resize(1);
  one.position.resize(1);
  EXPECT_THROW(PoseSpline(one, {}), std::invalid_argument);
  PoseSequence repeated = s;
  repeated.time[2] = repeated.time[1];
  try {
    PoseSpline bad(repeated, {});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sample 2"), std::string::npos) << e.what();
  }
  PoseSplineOptions o;
  o.order = 0;
  EXPECT_THROW(PoseSpline(s, o), std::invalid_argument);
  const PoseSpline ok(s, {});
  EXPECT_THROW(ok.evaluate(0.2000001), std::out_of_range);
  EXPECT_THROW(resample(s, std::vector<double>{-0.1}, {}), std::out_of_range);
}

TEST(PoseSplineWindow, MatchesTheBatchSplineAwayFromTheEnd) {
  PoseSequence s;
  for (int i = 0; i < 60; ++i) {
    const double t = 0.01 * i + 0.002 * ((i * 7) % 5);
    s.time.push_back(t);
    s.orientation.push_back(so3::exp(Vec3(std::sin(3 * t), std::cos(2 * t), t)));
    s.position.push_back(Vec3(std::sin(t), t * t, 1.0));
  }
  for (auto e : kEstimators) {
    PoseSplineOptions o;
    o.velocity.estimator = e;
    o.velocity.fit_half_width = 3;
    o.order = 3;
    const PoseSpline batch(s, o);
    PoseSplineWindow window(12, o, true);
    EXPECT_FALSE(window.ready_range().has_value());
    const std::size_t lookahead = window.lookahead();
    EXPECT_EQ(lookahead, e == KnotVelocityEstimator::LocalQuadraticFit ? 3u : 1u);
    for (std::size_t i = 0; i < s.size(); ++i) {
      ASSERT_TRUE(window.push(s.time[i], s.orientation[i], s.position[i]));
      EXPECT_FALSE(window.push(s.time[i], s.orientation[i], s.position[i]));  // not increasing
      const auto range = window.ready_range();
      if (i >= 2 * lookahead + 1) {
        ASSERT_TRUE(range.has_value()) << i;
        EXPECT_EQ(range->second, s.time[i - lookahead]);
        SplinePose live;
        for (double x : {0.0, 0.3, 0.77, 1.0}) {
          const double t = range->first + x * (range->second - range->first);
          ASSERT_TRUE(window.evaluate(t, live));
          const SplinePose ref = batch.evaluate(t);
          EXPECT_LT(so3::rotation_angle(live.orientation, ref.orientation), 1e-12) << i;
          EXPECT_LT((live.position - ref.position).norm(), 1e-12) << i;
        }
        EXPECT_FALSE(window.evaluate(range->second + 1e-6, live));
      }
      EXPECT_LE(window.size(), 12u);
    }
    window.clear();
    EXPECT_EQ(window.size(), 0u);
    EXPECT_FALSE(window.ready_range().has_value());
  }
  PoseSplineOptions fit;
  fit.velocity.estimator = KnotVelocityEstimator::LocalQuadraticFit;
  fit.velocity.fit_half_width = 3;
  EXPECT_THROW(PoseSplineWindow(7, fit, false), std::invalid_argument);
}

}  // namespace
}  // namespace posefair::geometric_splines
