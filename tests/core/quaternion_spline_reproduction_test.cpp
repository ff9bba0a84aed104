// Ramamoorthi & Barr Section 4 on the 7-keyframe example (one quaternion component always zero,
// zero end velocities). The tolerances are the measured values with a margin; where the paper's
// claim does not hold on this example the test asserts what does (docs/quaternion-splines.md).
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "posefair/core/quaternion_spline.hpp"
#include "posefair/core/quaternion_spline_example.hpp"
#include "posefair/core/quaternion_spline_study.hpp"

namespace posefair {
namespace {

const QuaternionSplineResult& four_frames() {
  static const QuaternionSplineResult r = [] {
    QuaternionSplineOptions o;  // α = 1000, 5 segments per interval, one frame per round
    o.variable_frames = 4;
    return build_quaternion_spline(seven_keyframe_example(), o);
  }();
  return r;
}

const QuaternionSplineResult& all_segment_frames() {
  static const QuaternionSplineResult r = [] {
    QuaternionSplineOptions o;
    o.variable_frames = 24;  // every non-keyframe segment start (6 intervals × 4)
    o.frames_per_round = 24;
    return build_quaternion_spline(seven_keyframe_example(), o);
  }();
  return r;
}

// The optimum estimated with many variable frames: the 24-frame optimum with every piece split
// once more (54 variable frames), optimised again.
double optimum_estimate() {
  static const double value = [] {
    QuaternionSpline s = all_segment_frames().spline;
    split_every_piece(s);
    OptimizerSettings settings;
    settings.max_evaluations = 100000;
    return optimize_spline(s, SplineObjective(1000.0, 8), settings).objective;
  }();
  return value;
}

TEST(QuaternionSplineReproduction, EachStageLowersTheObjectiveLikeFigure3) {
  const auto& st = four_frames().stages;
  ASSERT_EQ(st.size(), 6u);  // no optimisation, velocities only, 1..4 variable frames
  EXPECT_FALSE(st[0].optimized);
  EXPECT_EQ(st[1].variable_frames, 0);
  for (std::size_t i = 1; i < st.size(); ++i) {
    EXPECT_LT(st[i].objective, st[i - 1].objective) << i;
    EXPECT_GE(st[i].seconds, st[i - 1].seconds);
  }
  EXPECT_EQ(st[5].variable_frames, 4);
  // Optimising the velocities alone removes more than half of the unoptimised objective.
  EXPECT_LT(st[1].objective, 0.5 * st[0].objective);
}

TEST(QuaternionSplineReproduction, FourVariableFramesAreWithinOnePercentOfTheOptimum) {
  const double optimum = optimum_estimate();
  const double four = four_frames().stages.back().objective;
  const double gap = (four - optimum) / optimum;
  // The paper reports 0.1 % with 4 frames; here it is 0.53 %: within 1 %, not within 0.1 %.
  EXPECT_GT(gap, 0.0);
  EXPECT_LT(gap, 0.01);
  // With every segment start a variable frame (24) the gap is below 0.1 %.
  const double all = all_segment_frames().stages.back().objective;
  EXPECT_LT((all - optimum) / optimum, 1e-3);
  // And the estimate itself has settled: 54 frames improve on 24 by less than 0.05 %.
  EXPECT_LT((all - optimum) / optimum, 5e-4);
}

TEST(QuaternionSplineReproduction, UnitNormIsKeptWithinThePapersBounds) {
  const auto& st = four_frames().stages;
  EXPECT_GT(st[0].max_norm_deviation, 0.03);   // the unoptimised path: 4.5 %
  EXPECT_LT(st.back().max_norm_deviation, 0.01);  // α = 1000, 4 frames: under 1 % (0.26 %)
  QuaternionSplineOptions o;
  o.alpha = 10000.0;
  o.variable_frames = 24;
  o.frames_per_round = 24;
  const QuaternionSplineResult r = build_quaternion_spline(seven_keyframe_example(), o);
  EXPECT_EQ(r.spline.variable_frames(), 24);
  EXPECT_LT(r.stages.back().max_norm_deviation, 7e-4);  // paper: 0.07 %; here 0.022 %
}

TEST(QuaternionSplineReproduction, EulerLagrangeErrorDropsWithOptimisation) {
  const auto& st = four_frames().stages;
  EXPECT_LT(st.back().mean_el_deviation, 0.2 * st[0].mean_el_deviation);
  EXPECT_LT(st.back().max_el_deviation, 0.2 * st[0].max_el_deviation);
}

TEST(QuaternionSplineReproduction, KeyframesStayAndVariableFramesSitBetweenThem) {
  const QuaternionSplineResult& r = four_frames();
  const SplineKeyframes keys = seven_keyframe_example();
  std::size_t key = 0;
  for (std::size_t i = 0; i < r.spline.curve.nodes().size(); ++i) {
    const HermiteNode& n = r.spline.curve.nodes()[i];
    if (r.spline.is_variable_frame[i]) {
      EXPECT_TRUE(std::none_of(keys.time.begin(), keys.time.end(), [&](double t) { return t == n.time; }));
      continue;
    }
    ASSERT_LT(key, keys.time.size());
    EXPECT_EQ(n.time, keys.time[key]);
    EXPECT_LT((n.position - to_vec4(keys.orientation[key])).norm(), 1e-15);
    ++key;
  }
  EXPECT_EQ(key, keys.time.size());
  EXPECT_EQ(r.spline.curve.nodes().front().velocity, Vec4::Zero());
  EXPECT_EQ(r.spline.curve.nodes().back().velocity, Vec4::Zero());
}

TEST(QuaternionSplineReproduction, TheZeroComponentStaysZero) {
  // The objective is symmetric under z -> −z, so its gradient has no z part: the path stays on
  // the 2-sphere of the keyframes, as in the paper's Fig. 1.
  const HermiteCurve4& c = all_segment_frames().spline.curve;
  for (double t = 0.0; t <= 6.0; t += 0.01) EXPECT_EQ(c.position(t)(3), 0.0);
}

// Seeded key sets of the example's kind (docs/quaternion-splines.md has 10 of each, against the
// 54-frame optimum estimate): "within 0.1 % with 4 variable frames" holds for keys 10°-20° apart
// on S³ and not for keys 30°-50° apart like the example's; the norm's time-average deviation is
// about a third of its maximum, not the paper's tenth, with either. To stay fast under the
// sanitizers the gap is taken to the 24-frame optimum, which lies within 0.005 % of the estimate
// on every set there: the true gap is at least this one, and at most 0.005 % more.
TEST(QuaternionSplineReproduction, FourFramesWithinATenthOfAPercentDependsOnTheKeySteps) {
  auto run = [](const SplineKeyframes& keys, int frames) {
    QuaternionSplineOptions o;
    o.variable_frames = frames;
    o.frames_per_round = frames == 24 ? 24 : 1;
    return build_quaternion_spline(keys, o);
  };
  for (const bool large : {true, false}) {
    const SplineKeyframes keys = large ? random_seven_keyframes(1, 30.0, 50.0) : random_seven_keyframes(1, 10.0, 20.0);
    const QuaternionSplineResult four = run(keys, 4);
    const double best = run(keys, 24).stages.back().objective;
    const double gap = (four.stages.back().objective - best) / best;
    EXPECT_GT(gap, 0.0);
    if (large) {
      EXPECT_GT(gap, 1e-3);
      EXPECT_LT(gap, 1e-2);
    } else {
      EXPECT_LT(gap, 1e-3 - 5e-5);
    }
    const double max_dev = max_norm_deviation(four.spline.curve);
    EXPECT_LT(max_dev, 0.01);
    const double ratio = mean_norm_deviation(four.spline.curve) / max_dev;
    EXPECT_GT(ratio, 0.2) << large;
    EXPECT_LT(ratio, 0.5) << large;
  }
}
}  // namespace
}  // namespace posefair
