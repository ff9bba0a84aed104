// Alexa's operators (eqs. 1-3), the change of origin (eq. 7) and the pi/2 step check.
#include <cmath>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "posefair/core/eigen_matrix_functions.hpp"
#include "posefair/core/linear_combination.hpp"
#include "../support/affine_matrices.hpp"

namespace posefair {
namespace {

using ::testing::HasSubstr;
using testing::affine;
using testing::rel;
using testing::rot;
const CombinationOptions kP = CombinationOptions::precise();  // the paper's constants: ~1e-4 only

const Mat4 kA = affine(rot(0.7, {1, 2, 0}) * Eigen::Vector3d(1.5, 0.8, 1.1).asDiagonal(), {2, -1, 4});
const Mat4 kB = affine(rot(1.1, {0, 1, 1}) * Eigen::Vector3d(0.9, 1.2, 2.0).asDiagonal(), {-3, 0.5, 1});

TEST(AlexaOperators, ScalarMultiplicationIsAPower) {
  EXPECT_LT(rel(scale(2.0, kA, kP).value(), kA * kA), 1e-6);
  EXPECT_LT(rel(scale(0.5, kA, kP).value(), eigen_matrix_sqrt(kA)), 1e-6);
  EXPECT_LT(rel(scale(-1.0, kA, kP).value(), kA.inverse()), 1e-6);
  EXPECT_LT(rel(scale(0.0, kA, kP).value(), Mat4::Identity()), 1e-12);
}

TEST(AlexaOperators, AdditionIsCommutativeAndTheProductForCommutingMatrices) {
  const Mat4 r1 = affine(rot(0.4, {0, 0, 1}), Eigen::Vector3d::Zero());
  const Mat4 r2 = affine(rot(0.9, {0, 0, 1}), Eigen::Vector3d::Zero());
  EXPECT_LT(rel(add(r1, r2, kP).value(), r1 * r2), 1e-6);
  EXPECT_LT(rel(add(kA, kB, kP).value(), add(kB, kA, kP).value()), 1e-12);
  EXPECT_GT(rel(add(kA, kB, kP).value(), kA * kB), 1e-3);  // non-commuting: not the product
}

TEST(Lerp, HitsBothEndsAndTranslatesLinearly) {
  EXPECT_LT(rel(lerp(kA, kB, 0.0, kP).value(), kA), 1e-12);
  EXPECT_LT(rel(lerp(kA, kB, 1.0, kP).value(), kB), 1e-6);
  const Mat4 ta = affine(Eigen::Matrix3d::Identity(), {1, 2, 3}), tb = affine(Eigen::Matrix3d::Identity(), {-5, 0, 9});
  const Mat4 mid = lerp(ta, tb, 0.25, kP).value();
  EXPECT_LT((mid.topRightCorner<3, 1>() - Eigen::Vector3d(-0.5, 1.5, 4.5)).norm(), 1e-7);
}

TEST(Lerp, RotatesAboutTheRelativeAxisAtConstantRate) {
  const Mat4 a = affine(rot(2.5, {1, 0, 0}), Eigen::Vector3d::Zero());  // large absolute rotations ...
  const Mat4 b = affine(rot(1.2, {0, 1, 0}) * rot(2.5, {1, 0, 0}), Eigen::Vector3d::Zero());  // ... 1.2 rad apart
  for (double t : {0.2, 0.5, 0.8}) {
    const Mat4 m = lerp(a, b, t, kP).value();
    const Eigen::Matrix3d step = m.topLeftCorner<3, 3>() * a.topLeftCorner<3, 3>().transpose();
    EXPECT_NEAR(Eigen::AngleAxisd(step).angle(), 1.2 * t, 1e-6);
  }
}

TEST(Lerp, DirectAndAboutTheOriginAgreeForCommutingKeys) {
  const Mat4 a = affine(rot(0.3, {0, 0, 1}) * 2.0, Eigen::Vector3d::Zero());
  const Mat4 b = affine(rot(1.0, {0, 0, 1}) * 0.5, Eigen::Vector3d::Zero());
  EXPECT_LT(rel(lerp(a, b, 0.4, kP).value(), lerp_direct(a, b, 0.4, kP).value()), 1e-6);
}

TEST(Lerp, RefusesAStepOfAQuarterTurnOrMoreAndAsksForAKeyframe) {
  const Mat4 a = affine(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  const Mat4 b = affine(rot(std::numbers::pi / 2 + 1e-3, {0, 0, 1}), Eigen::Vector3d::Zero());
  const MatrixResult r = lerp(a, b, 0.5, kP);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, MatrixErrorCode::UnsafeStep);
  EXPECT_THAT(r.error().message, HasSubstr("add a keyframe"));
  const Mat4 c = affine(rot(std::numbers::pi / 2 - 1e-2, {0, 0, 1}), Eigen::Vector3d::Zero());
  EXPECT_TRUE(lerp(a, c, 0.5, kP));
}

TEST(Lerp, TheChangeOfOriginRescuesLargeAbsoluteRotationsWithNonUniformScale) {
  // Both keys rotate by 170 degrees with non-uniform scale: no principal logarithm each.
  const Eigen::Matrix3d s = Eigen::Vector3d(1, 4, 1).asDiagonal();
  const Mat4 a = affine(rot(170 * std::numbers::pi / 180, {0, 0, 1}) * s, {1, 0, 0});
  const Mat4 b = affine(rot(200 * std::numbers::pi / 180, {0, 0, 1}) * s, {0, 1, 0});
  EXPECT_FALSE(lerp_direct(a, b, 0.5, kP));
  const MatrixResult m = lerp(a, b, 0.5, kP);
  ASSERT_TRUE(m) << m.error().message;
  // Halfway: 185 degrees about z, the scale kept.
  const Mat4 expected = affine(rot(185 * std::numbers::pi / 180, {0, 0, 1}) * s, Eigen::Vector3d::Zero());
  EXPECT_LT((m.value().topLeftCorner<3, 3>() - expected.topLeftCorner<3, 3>()).norm(), 1e-6);
}

TEST(PreparedLerp, EqualsLerpAndAcceptsAnyOrigin) {
  const auto p = PreparedLerp::make(kA, kB, kP);
  ASSERT_TRUE(p);
  for (double t : {0.0, 0.3, 0.9}) EXPECT_LT(rel(p.value().at(t).value(), lerp(kA, kB, t, kP).value()), 1e-12);
  const Mat4 x = affine(rot(0.2, {1, 1, 1}), {0.3, 0.3, 0});
  const auto q = PreparedLerp::make(kA, kB, x, kP);
  ASSERT_TRUE(q);
  EXPECT_LT(rel(q.value().at(0.0).value(), kA), 1e-6);
  EXPECT_LT(rel(q.value().at(1.0).value(), kB), 1e-6);
}

TEST(Combine, WeightsOfTranslationsAreAnAffineCombination) {
  std::vector<Mat4> m;
  for (int i = 0; i < 4; ++i) m.push_back(affine(Eigen::Matrix3d::Identity(), Eigen::Vector3d(i, i * i, 1)));
  const std::vector<double> w{-1.0 / 16, 9.0 / 16, 9.0 / 16, -1.0 / 16};
  const MatrixResult c = combine(w, m, m[1], kP);
  ASSERT_TRUE(c);
  EXPECT_LT((c.value().topRightCorner<3, 1>() - Eigen::Vector3d(1.5, 2.25, 1.0)).norm(), 1e-7);
}

TEST(RotationalComponent, IsThePolarRotationAngle) {
  EXPECT_NEAR(rotational_component(affine(rot(0.8, {1, 0, 0}) * Eigen::Vector3d(1, 5, 1).asDiagonal(), {9, 9, 9})),
              0.8, 1e-12);
  EXPECT_NEAR(rotational_component(Mat4(Eigen::Vector4d(1, 1, -1, 1).asDiagonal())), std::numbers::pi, 1e-12);
}

}  // namespace
}  // namespace posefair
