// B-spline weights (eq. 8), the unrolled 4-point subdivision (eqs. 9-16, ERRATA item 1) and
// frames from keyframe matrices.
#include <cmath>
#include <algorithm>
#include <numeric>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "posefair/core/keyframe_interpolation.hpp"

namespace posefair {
namespace {

double dense_value(const FrameWeights& f, const std::vector<double>& values) {
  double s = 0.0;
  for (const WeightTerm& t : f.terms) s += t.weight * values[t.key];
  return s;
}

TEST(BSplineWeights, PartitionOfUnityNonNegativeAndClampedEnds) {
  const std::vector<double> keys{0.0, 1.0, 1.5, 4.0, 5.0, 7.5, 8.0};
  const auto knots = bspline_knots(keys, 3);
  ASSERT_EQ(knots.size(), keys.size() + 4);
  for (double t = 0.0; t <= 8.0; t += 0.05) {
    const auto b = bspline_basis(knots, static_cast<int>(keys.size()), 3, t);
    EXPECT_NEAR(std::accumulate(b.begin(), b.end(), 0.0), 1.0, 1e-12);
    for (double w : b) EXPECT_GE(w, 0.0);
    EXPECT_LE(std::count_if(b.begin(), b.end(), [](double w) { return w > 0.0; }), 4);
  }
  EXPECT_NEAR(bspline_basis(knots, 7, 3, 0.0)[0], 1.0, 1e-15);
  EXPECT_NEAR(bspline_basis(knots, 7, 3, 8.0)[6], 1.0, 1e-15);
}

TEST(BSplineWeights, AreTwiceContinuouslyDifferentiableAcrossInteriorKnots) {
  const std::vector<double> keys{0.0, 1.0, 1.5, 4.0, 5.0, 7.5, 8.0};
  const auto knots = bspline_knots(keys, 3);
  const double h = 1e-3;
  for (int k = 4; k < 7; ++k) {
    const double u = knots[k];
    auto f = [&](double t) { return bspline_basis(knots, 7, 3, t); };
    const auto l2 = f(u - 2 * h), l1 = f(u - h), c = f(u), r1 = f(u + h), r2 = f(u + 2 * h);
    for (int i = 0; i < 7; ++i) {
      // One-sided second differences on both sides agree (a jump in N'' would show as O(1)).
      const double left = (c[i] - 2 * l1[i] + l2[i]) / (h * h), right = (r2[i] - 2 * r1[i] + c[i]) / (h * h);
      EXPECT_NEAR(left, right, 0.05) << "knot " << u << " basis " << i;
    }
  }
}

TEST(Subdivision, KeepsTheKeysAndReproducesLinearDataUpToTheEnds) {
  for (int n : {2, 3, 5}) {
    const int levels = 4;
    const auto rows = subdivision_weights(n, levels);
    ASSERT_EQ(static_cast<int>(rows.size()), (n - 1) * 16 + 1);
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < n; ++k) EXPECT_EQ(rows[i * 16][k], i == k ? 1.0 : 0.0);
    // ERRATA item 1: with the dummy M_-1 = 2 M_0 - M_1 (in log space) linear data stay linear
    // at the ends. The printed eqs. 13-14 (M_-1 = 2 M_1 - M_0) bend them.
    for (std::size_t r = 0; r < rows.size(); ++r) {
      double v = 0.0, sum = 0.0;
      for (int k = 0; k < n; ++k) {
        v += rows[r][k] * k;
        sum += rows[r][k];
      }
      EXPECT_NEAR(sum, 1.0, 1e-12);
      EXPECT_NEAR(v, r / 16.0, 1e-12);
    }
  }
}

TEST(Subdivision, ReproducesCubicsInTheInterior) {
  const int n = 8;
  const auto rows = subdivision_weights(n, 3);
  for (std::size_t r = 3 * 8; r <= 4 * 8; ++r) {  // between keys 3 and 4: far from the ends
    double v = 0.0;
    for (int k = 0; k < n; ++k) v += rows[r][k] * k * k * k;
    const double x = r / 8.0;
    EXPECT_NEAR(v, x * x * x, 1e-9);
  }
}

TEST(Subdivision, LevelRuleFollowsThePaper) {
  EXPECT_EQ(subdivision_levels(5, 4), 0);   // 5 points > 4 frames
  EXPECT_EQ(subdivision_levels(5, 5), 1);   // 9 > 5
  EXPECT_EQ(subdivision_levels(5, 100), 5); // 129 > 100 > 65
}

TEST(FrameWeights, ResampledSubdivisionPassesThroughKeysAtTheirTimes) {
  const std::vector<double> keys{0.0, 10.0, 15.0, 40.0};
  std::vector<double> frames;
  for (int f = 0; f <= 40; ++f) frames.push_back(f);
  const std::vector<double> values{1.0, -2.0, 5.0, 0.5};
  const auto w = frame_weights(InterpolationMethod::Subdivision, keys, frames);
  ASSERT_EQ(w.size(), frames.size());
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(dense_value(w[static_cast<int>(keys[i])], values), values[i], 1e-12);
  // Each frame is a single pass over keys (eqs. 15-16): weights sum to 1, origin = largest.
  for (const auto& f : w) {
    double sum = 0.0, best = -1.0;
    for (const auto& t : f.terms) {
      sum += t.weight;
      best = std::max(best, t.weight);
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
    const auto o = std::find_if(f.terms.begin(), f.terms.end(), [&](const WeightTerm& t) { return t.key == f.origin; });
    ASSERT_NE(o, f.terms.end());
    EXPECT_EQ(o->weight, best);
  }
}

TEST(FrameWeights, LinearUsesTheSegmentsFirstKeyAsOrigin) {
  const std::vector<double> keys{0.0, 2.0, 3.0};
  const std::vector<double> frames{-1.0, 0.5, 2.5, 3.0, 9.0};
  const auto w = frame_weights(InterpolationMethod::Linear, keys, frames);
  EXPECT_EQ(w[0].terms.size(), 1u);
  EXPECT_EQ(w[0].terms[0].key, 0);
  EXPECT_EQ(w[1].origin, 0);
  EXPECT_NEAR(w[1].terms[1].weight, 0.25, 1e-15);
  EXPECT_EQ(w[2].origin, 1);
  EXPECT_EQ(w[4].terms.back().key, 2);
  EXPECT_THROW(frame_weights(InterpolationMethod::Linear, std::vector<double>{1.0, 1.0}, frames), std::invalid_argument);
}

Mat4 pose(double angle, const Eigen::Vector3d& p) {
  Mat4 m = Mat4::Identity();
  m.topLeftCorner<3, 3>() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  m.topRightCorner<3, 1>() = p;
  return m;
}

TEST(KeyframeInterpolation, RotationsAboutOneAxisFollowTheScalarSchemeOnTheAngle) {
  // Rotations about one axis commute, so every method acts on the angle like on numbers.
  const std::vector<double> keys{0, 1, 2, 3, 4};
  const std::vector<double> angles{0.0, 0.6, 1.0, 1.5, 1.8};  // any 4 consecutive within pi/2
  std::vector<Mat4> m;
  for (double a : angles) m.push_back(pose(a, Eigen::Vector3d::Zero()));
  std::vector<double> frames;
  for (int f = 0; f <= 40; ++f) frames.push_back(f / 10.0);
  for (auto method : {InterpolationMethod::Linear, InterpolationMethod::Approximating, InterpolationMethod::Subdivision}) {
    const auto r = interpolate_keyframes(method, keys, m, {}, frames, CombinationOptions::precise());
    ASSERT_TRUE(r) << r.error().message;
    const auto w = frame_weights(method, keys, frames);
    for (std::size_t f = 0; f < frames.size(); ++f) {
      const Eigen::Matrix3d got = r.value()[f].topLeftCorner<3, 3>();
      const Eigen::Matrix3d want = pose(dense_value(w[f], angles), Eigen::Vector3d::Zero()).topLeftCorner<3, 3>();
      EXPECT_LT((got - want).norm(), 1e-6) << "frame " << f;
    }
  }
}

TEST(KeyframeInterpolation, NamesTheKeyOfAnUnsafeStep) {
  const std::vector<double> keys{0, 1, 2};
  const std::vector<Mat4> m{pose(0.0, {0, 0, 0}), pose(0.5, {1, 0, 0}), pose(2.3, {2, 0, 0})};
  const std::vector<double> frames{0.0, 0.5, 1.0, 1.5, 2.0};
  const auto r = interpolate_keyframes(InterpolationMethod::Linear, keys, m, {}, frames);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, MatrixErrorCode::UnsafeStep);
  EXPECT_EQ(r.error().key, 2);
  EXPECT_EQ(r.error().origin_key, 1);
}

}  // namespace
}  // namespace posefair
