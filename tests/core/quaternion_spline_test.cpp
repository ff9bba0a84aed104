// The quaternion spline algorithm: objective and its analytic gradient, step 2's initial
// velocities, the optimiser, refinement, and the sampled comparison measures.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "posefair/core/quaternion_spline.hpp"
#include "posefair/core/quaternion_spline_example.hpp"
#include "posefair/core/sampled_rotation_energy.hpp"

namespace posefair {
namespace {

TEST(SplineObjective, QuadratureHasConverged) {
  const QuaternionSpline s = initial_spline(seven_keyframe_example());
  const double eight = SplineObjective(1000.0, 8).value(s.curve);
  const double thirty = SplineObjective(1000.0, 30).value(s.curve);
  // 1.4e-8 relative on this (far from unit norm) curve: far below the differences that matter.
  EXPECT_NEAR(eight, thirty, 1e-7 * thirty);
}

// Central finite differences of the objective against its analytic gradient, for every node
// quantity (positions of keyframes included, though the optimiser never moves those).
void expect_gradient_matches_finite_differences(HermiteCurve4 curve, double alpha) {
  const SplineObjective objective(alpha, 8);
  ObjectiveGradient g;
  objective.value_and_gradient(curve, g);
  EXPECT_NEAR(objective.value(curve), objective.value_and_gradient(curve, g), 1e-12 * objective.value(curve));
  const double h = 1e-6;
  double worst = 0.0;
  for (std::size_t i = 0; i < curve.nodes().size(); ++i) {
    for (int which = 0; which < 2; ++which) {
      for (int c = 0; c < 4; ++c) {
        Vec4& x = which == 0 ? curve.nodes()[i].position : curve.nodes()[i].velocity;
        const double keep = x(c);
        x(c) = keep + h;
        const double up = objective.value(curve);
        x(c) = keep - h;
        const double down = objective.value(curve);
        x(c) = keep;
        const double numeric = (up - down) / (2 * h);
        const double analytic = which == 0 ? g.d_position[i](c) : g.d_velocity[i](c);
        worst = std::max(worst, std::abs(numeric - analytic) / (1.0 + std::abs(numeric)));
      }
    }
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(SplineObjective, AnalyticGradientMatchesFiniteDifferences) {
  QuaternionSpline s = initial_spline(seven_keyframe_example());
  expect_gradient_matches_finite_differences(s.curve, 1000.0);
  // With variable frames and uneven pieces, after an optimisation.
  QuaternionSplineOptions o;
  o.variable_frames = 3;
  const QuaternionSplineResult r = build_quaternion_spline(seven_keyframe_example(), o);
  expect_gradient_matches_finite_differences(r.spline.curve, 1000.0);
  expect_gradient_matches_finite_differences(r.spline.curve, 0.0);
}

TEST(InitialSpline, CentralDifferencesInsideOneSidedAtFreeEnds) {
  SplineKeyframes k = seven_keyframe_example();
  k.time = {0.0, 1.0, 2.5, 3.0, 4.0, 5.0, 7.0};
  k.omega_start.reset();
  k.omega_end.reset();
  const QuaternionSpline s = initial_spline(k);
  const auto& n = s.curve.nodes();
  ASSERT_EQ(n.size(), 7u);
  for (std::size_t i = 1; i + 1 < n.size(); ++i)
    EXPECT_LT((n[i].velocity - (n[i + 1].position - n[i - 1].position) / (n[i + 1].time - n[i - 1].time)).norm(), 1e-15);
  EXPECT_LT((n[0].velocity - (n[1].position - n[0].position) / 1.0).norm(), 1e-15);
  EXPECT_LT((n[6].velocity - (n[6].position - n[5].position) / 2.0).norm(), 1e-15);
  EXPECT_TRUE(s.velocity_free(0));
  EXPECT_TRUE(s.velocity_free(6));
  EXPECT_EQ(s.free_parameters(), 7 * 4);
}

TEST(InitialSpline, EndAngularVelocitiesBecomeQuaternionVelocities) {
  SplineKeyframes k = seven_keyframe_example();
  k.omega_start = Vec3(0.5, -1.0, 2.0);
  k.omega_end = Vec3(0.0, 0.3, 0.0);
  const QuaternionSpline s = initial_spline(k);
  const auto& n = s.curve.nodes();
  // q′ = ½ ω q, and conversely ω = 2 q′ q⁻¹ (eq. 2).
  const Quat q0 = to_quat(n[0].position), dq0 = to_quat(n[0].velocity);
  EXPECT_LT(((dq0 * q0.conjugate()).coeffs() * 2.0 - Quat(0, 0.5, -1.0, 2.0).coeffs()).norm(), 1e-14);
  const Quat q6 = to_quat(n[6].position), dq6 = to_quat(n[6].velocity);
  EXPECT_LT(((dq6 * q6.conjugate()).coeffs() * 2.0 - Quat(0, 0.0, 0.3, 0.0).coeffs()).norm(), 1e-14);
  EXPECT_FALSE(s.velocity_free(0));
  EXPECT_FALSE(s.velocity_free(6));
  EXPECT_EQ(s.free_parameters(), 5 * 4);
}

TEST(InitialSpline, KeysAreNormalisedAndPutInOneHemisphere) {
  SplineKeyframes k;
  k.time = {0.0, 1.0, 2.0};
  k.orientation = {Quat(2, 0, 0, 0), Quat(-0.9, -0.1, 0, 0), Quat(0.8, 0.2, 0, 0)};
  const QuaternionSpline s = initial_spline(k);
  for (const HermiteNode& n : s.curve.nodes()) EXPECT_NEAR(n.position.norm(), 1.0, 1e-15);
  EXPECT_GT(s.curve.nodes()[0].position.dot(s.curve.nodes()[1].position), 0.0);
  EXPECT_GT(s.curve.nodes()[1].position.dot(s.curve.nodes()[2].position), 0.0);
}

TEST(InitialSpline, RejectsBadKeyframes) {
  SplineKeyframes k;
  k.time = {0.0};
  k.orientation = {Quat::Identity()};
  EXPECT_THROW(initial_spline(k), std::invalid_argument);
  k.time = {0.0, 1.0, 1.0};
  k.orientation = {Quat::Identity(), Quat::Identity(), Quat::Identity()};
  EXPECT_THROW(initial_spline(k), std::invalid_argument);
  k.time = {0.0, 1.0, 2.0};
  k.orientation[1] = Quat(0, 0, 0, 0);
  EXPECT_THROW(initial_spline(k), std::invalid_argument);
}

TEST(OptimizeSpline, KeepsKeyframesAndGivenEndVelocitiesAndLowersTheObjective) {
  SplineKeyframes k = seven_keyframe_example();
  k.omega_end = Vec3(0.2, 0.1, 0.0);
  QuaternionSpline s = initial_spline(k);
  const QuaternionSpline before = s;
  const SplineObjective objective(1000.0, 8);
  const OptimizeReport rep = optimize_spline(s, objective, {});
  EXPECT_LT(rep.objective, 0.6 * objective.value(before.curve));
  EXPECT_NEAR(rep.objective, objective.value(s.curve), 1e-12 * rep.objective);
  for (std::size_t i = 0; i < s.curve.nodes().size(); ++i)
    EXPECT_EQ(s.curve.nodes()[i].position, before.curve.nodes()[i].position);
  EXPECT_EQ(s.curve.nodes().front().velocity, before.curve.nodes().front().velocity);
  EXPECT_EQ(s.curve.nodes().back().velocity, before.curve.nodes().back().velocity);
  EXPECT_NE(s.curve.nodes()[3].velocity, before.curve.nodes()[3].velocity);
  // At the optimum the gradient with respect to the free velocities vanishes.
  ObjectiveGradient g;
  objective.value_and_gradient(s.curve, g);
  for (std::size_t i = 1; i + 1 < s.curve.nodes().size(); ++i) EXPECT_LT(g.d_velocity[i].norm(), 1e-3) << i;
}

TEST(OptimizeSpline, LbfgsAndSlsqpReachTheSameOptimum) {
  for (int frames : {0, 4}) {
    QuaternionSplineOptions o;
    o.variable_frames = frames;
    o.optimizer.method = SplineOptimizer::Lbfgs;
    const QuaternionSplineResult a = build_quaternion_spline(seven_keyframe_example(), o);
    o.optimizer.method = SplineOptimizer::Slsqp;
    const QuaternionSplineResult b = build_quaternion_spline(seven_keyframe_example(), o);
    ASSERT_EQ(a.stages.size(), b.stages.size());
    for (std::size_t i = 0; i < a.stages.size(); ++i)
      EXPECT_NEAR(a.stages[i].objective, b.stages[i].objective, 1e-6 * b.stages[i].objective) << frames << " " << i;
  }
}

TEST(Refinement, SegmentsCutEveryKeyIntervalEvenly) {
  const std::vector<double> t{0.0, 1.0, 3.0};
  const auto s = refinement_segments(t, 4);
  ASSERT_EQ(s.size(), 8u);
  EXPECT_TRUE(s[0].starts_at_keyframe);
  EXPECT_FALSE(s[1].starts_at_keyframe);
  EXPECT_TRUE(s[4].starts_at_keyframe);
  EXPECT_DOUBLE_EQ(s[5].start, 1.5);
  EXPECT_DOUBLE_EQ(s[7].end, 3.0);
}

TEST(Refinement, FramesGoToTheWorstSegmentsAwayFromKeyframes) {
  QuaternionSpline s = initial_spline(seven_keyframe_example());
  const auto segments = refinement_segments(seven_keyframe_example().time, 5);
  std::vector<double> dev(segments.size(), 0.0);
  dev[0] = 100.0;  // starts at a keyframe: never used
  dev[7] = 50.0;
  dev[13] = 40.0;
  dev[3] = 30.0;
  EXPECT_EQ(add_variable_frames(s, segments, dev, 2), 2);
  EXPECT_EQ(s.variable_frames(), 2);
  std::vector<double> frame_times;
  for (std::size_t i = 0; i < s.curve.nodes().size(); ++i)
    if (s.is_variable_frame[i]) frame_times.push_back(s.curve.nodes()[i].time);
  ASSERT_EQ(frame_times.size(), 2u);
  EXPECT_DOUBLE_EQ(frame_times[0], segments[7].start);
  EXPECT_DOUBLE_EQ(frame_times[1], segments[13].start);
  // The same segments again: those already hold frames, so the next best is taken.
  EXPECT_EQ(add_variable_frames(s, segments, dev, 1), 1);
  EXPECT_EQ(s.curve.nodes()[1].time, segments[3].start);
  // Every non-keyframe segment start filled: nothing more can be added.
  EXPECT_EQ(add_variable_frames(s, segments, std::vector<double>(segments.size(), 1.0), 100), 21);
  EXPECT_EQ(add_variable_frames(s, segments, dev, 1), 0);
  EXPECT_EQ(s.variable_frames(), 24);
}

TEST(Refinement, TargetImprovementStopsEarly) {
  QuaternionSplineOptions o;
  o.variable_frames = 24;
  o.target_improvement = 1e-3;
  const QuaternionSplineResult r = build_quaternion_spline(seven_keyframe_example(), o);
  const int frames = r.spline.variable_frames();
  EXPECT_LT(frames, 24);
  const auto& last = r.stages.back();
  const auto& previous = r.stages[r.stages.size() - 2];
  EXPECT_LT(previous.objective - last.objective, 1e-3 * last.objective);
  for (std::size_t i = 2; i + 1 < r.stages.size(); ++i)
    EXPECT_GE(r.stages[i - 1].objective - r.stages[i].objective, 1e-3 * r.stages[i].objective) << i;
}

TEST(SampledEnergy, SlerpChainCornersGrowLikeOneOverDt) {
  const SplineKeyframes k = seven_keyframe_example();
  auto energy = [&](double dt) {
    const auto t = uniform_times(0.0, 6.0, dt);
    return sampled_covariant_energy(slerp_chain(k.time, k.orientation, t), dt);
  };
  const double coarse = energy(0.01), fine = energy(0.005);
  EXPECT_NEAR(fine / coarse, 2.0, 0.05);
  // Between corners a slerp is a great circle at constant speed: no covariant acceleration.
  const auto t = uniform_times(1.1, 1.9, 0.01);
  EXPECT_LT(sampled_covariant_energy(slerp_chain(k.time, k.orientation, t), 0.01), 1e-8);
}

TEST(SampledEnergy, ApproachesTheContinuousCovariantPartOnTheOptimisedSpline) {
  QuaternionSplineOptions o;
  o.variable_frames = 4;
  const QuaternionSplineResult r = build_quaternion_spline(seven_keyframe_example(), o);
  const double continuous = SplineObjective(o.alpha, 8).covariant_part(r.spline.curve);
  const double dt = 0.002;
  std::vector<Quat> samples;
  for (double t : uniform_times(0.0, 6.0, dt)) samples.push_back(to_quat(r.spline.curve.position(t)));
  // Normalising the samples changes the path by at most its norm deviation (0.3 %).
  EXPECT_NEAR(sampled_covariant_energy(samples, dt), continuous, 0.03 * continuous);
}

}  // namespace
}  // namespace posefair
