// Matrix exponential, square root and logarithm (Hawkins & Grimm Section 4) against Eigen's
// MatrixFunctions, and every error case.
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "posefair/core/eigen_matrix_functions.hpp"
#include "posefair/core/matrix_functions.hpp"
#include "posefair/core/matrix_interpolation_study.hpp"
#include "../support/affine_matrices.hpp"

namespace posefair {
namespace {

using ::testing::HasSubstr;
using testing::affine;
using testing::rel;
using testing::rot;

TEST(MatrixExp, MatchesEigenOverManyScales) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> g;
  for (double size : {1e-6, 0.1, 1.0, 5.0, 40.0}) {
    for (int i = 0; i < 50; ++i) {
      Mat4 a;
      for (int k = 0; k < 16; ++k) a(k / 4, k % 4) = size * g(rng) / 4.0;
      const MatrixResult x = matrix_exp(a);
      ASSERT_TRUE(x) << x.error().message;
      const Mat4 ref = eigen_matrix_exp(a);
      // Pade (6,6) after scaling to |A| < 1 is accurate to ~1e-15 per step; squarings add a
      // little relative error each.
      EXPECT_LT(rel(x.value(), ref), 1e-10) << "size " << size;
    }
  }
}

TEST(MatrixExp, ZeroGivesIdentityAndScalingExponentIsAnInteger) {
  EXPECT_EQ(matrix_exp(Mat4::Zero()).value(), Mat4::Identity());
  // ERRATA item 2: a norm just above a power of two still needs whole squarings; the result of
  // a diagonal matrix is exact to rounding.
  const Mat4 d = Eigen::Vector4d(2.5, -1.0, 0.3, 0.0).asDiagonal();
  const Mat4 x = matrix_exp(d).value();
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(x(i, i), std::exp(d(i, i)), 1e-13 * std::exp(d(i, i)));
}

TEST(MatrixExp, ReportsNonFiniteInputAndOverflow) {
  Mat4 a = Mat4::Identity();
  a(1, 2) = std::nan("");
  EXPECT_EQ(matrix_exp(a).error().code, MatrixErrorCode::NotFinite);
  EXPECT_EQ(matrix_exp(Mat4(1e4 * Mat4::Identity())).error().code, MatrixErrorCode::NotFinite);
}

TEST(MatrixSqrt, MatchesEigenOnTransformsWithAPrincipalRoot) {
  std::mt19937_64 rng(2);
  int checked = 0;
  for (int i = 0; i < 200; ++i) {
    const Mat4 a = random_test_transform(rng);
    if (check_principal_logarithm(a).index() == 1) continue;
    SqrtTrace t;
    const MatrixResult x = matrix_sqrt(a, {}, &t);
    if (!x) {
      EXPECT_EQ(x.error().code, MatrixErrorCode::NoConvergence);
      continue;
    }
    ++checked;
    EXPECT_LT(norm_inf(x.value() * x.value() - a), 1e-6);  // the stopping rule, eps3
    EXPECT_LT(rel(x.value(), eigen_matrix_sqrt(a)), 1e-6);
    EXPECT_LE(t.iterations, 10);
  }
  EXPECT_GT(checked, 50);
}

TEST(MatrixSqrt, RefusesANegativeRealEigenvalue) {
  // A half turn about z with non-uniform scale: eigenvalues -1 and -3 (ERRATA item 4).
  const Mat4 a = affine(rot(std::numbers::pi, Eigen::Vector3d::UnitZ()) * Eigen::Vector3d(1, 3, 1).asDiagonal(),
                        Eigen::Vector3d(1, 2, 3));
  const MatrixResult s = matrix_sqrt(a);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code, MatrixErrorCode::NoPrincipalLogarithm);
  EXPECT_THAT(s.error().message, HasSubstr("negative real eigenvalue"));
  // The bare iteration on it does not converge: the check is what prevents a wrong answer.
  EXPECT_FALSE(denman_beavers_sqrt(a));
}

TEST(MatrixSqrt, ReportsNonConvergenceAtTheIterationCap) {
  const Mat4 a = affine(rot(1.0, Eigen::Vector3d(1, 2, 3)) * Eigen::Vector3d(0.5, 2, 3).asDiagonal(),
                        Eigen::Vector3d(10, 2, 3));
  ASSERT_EQ(check_principal_logarithm(a).index(), 0);
  SqrtOptions o;
  o.max_iterations = 2;
  const MatrixResult s = matrix_sqrt(a, o);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code, MatrixErrorCode::NoConvergence);
  EXPECT_THAT(s.error().message, HasSubstr("add a keyframe"));
}

TEST(MatrixLog, MatchesEigenOnSection42Transforms) {
  std::mt19937_64 rng(3);
  int checked = 0, refused = 0;
  double worst = 0.0;
  for (int i = 0; i < 200; ++i) {
    const Mat4 a = random_test_transform(rng);
    LogTrace t;
    const MatrixResult l = matrix_log(a, {}, &t);
    if (!l) {
      // Either there is no principal logarithm, or an iteration hit its cap: never a matrix.
      ++refused;
      if (check_principal_logarithm(a).index() == 0) {
        EXPECT_EQ(l.error().code, MatrixErrorCode::NoConvergence);
      }
      continue;
    }
    ++checked;
    worst = std::max(worst, rel(l.value(), eigen_matrix_log(a)));
    EXPECT_LE(t.square_roots, 20);
    EXPECT_LE(t.series_terms, 7);
    EXPECT_LT(t.distance_to_identity, 1e-4);
  }
  EXPECT_GT(checked, 30);
  EXPECT_GT(refused, 0);  // the paper's distribution does produce matrices without a real log
  // The paper's constants: each root stops at |XX - A| < eps3 = 1e-6 and the series starts at
  // |B| < eps1 = 1e-4, so the log is only good to about 1e-4 relative (measured 5e-4 worst).
  EXPECT_LT(worst, 2e-3);
}

TEST(MatrixLog, PrecisePresetMatchesEigenTo1e9) {
  std::mt19937_64 rng(3);
  int checked = 0;
  for (int i = 0; i < 200; ++i) {
    const Mat4 a = random_test_transform(rng);
    const MatrixResult l = matrix_log(a, LogOptions::precise());
    if (!l) continue;
    ++checked;
    EXPECT_LT(rel(l.value(), eigen_matrix_log(a)), 1e-9);
  }
  EXPECT_GT(checked, 80);  // more roots allowed: also the matrices the paper's 20 roots cannot reach
}

TEST(MatrixLog, IsTheInverseOfExpNearTheIdentityAndForRigidMotions) {
  const Mat4 a = affine(rot(1.2, Eigen::Vector3d(0, 1, 1)), Eigen::Vector3d(3, -2, 0.5));
  EXPECT_LT(rel(matrix_log(a).value(), eigen_matrix_log(a)), 2e-3);  // the paper's constants
  const MatrixResult l = matrix_log(a, LogOptions::precise());
  ASSERT_TRUE(l);
  EXPECT_LT(rel(matrix_exp(l.value()).value(), a), 1e-9);
  EXPECT_LT(rel(l.value(), eigen_matrix_log(a)), 1e-9);
  // The rotation part of the log is skew with the rotation vector's norm as angle.
  const Eigen::Matrix3d w = l.value().topLeftCorner<3, 3>();
  EXPECT_LT((w + w.transpose()).norm(), 1e-7);
  EXPECT_NEAR(Eigen::Vector3d(w(2, 1), w(0, 2), w(1, 0)).norm(), 1.2, 1e-7);
}

TEST(MatrixLog, ReportsSingularReflectionNanAndCaps) {
  EXPECT_EQ(matrix_log(Mat4(Eigen::Vector4d(1, 2, 0, 1).asDiagonal())).error().code,
            MatrixErrorCode::NoPrincipalLogarithm);
  EXPECT_EQ(matrix_log(Mat4(Eigen::Vector4d(1, -2, 1, 1).asDiagonal())).error().code,
            MatrixErrorCode::NoPrincipalLogarithm);
  Mat4 n = Mat4::Identity();
  n(0, 3) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(matrix_log(n).error().code, MatrixErrorCode::NotFinite);
  const Mat4 a = Mat4(Eigen::Vector4d(50, 2, 1, 1).asDiagonal());
  LogOptions few_roots;
  few_roots.max_square_roots = 3;  // 50^(1/8) is still 1.6 from I
  EXPECT_EQ(matrix_log(a, few_roots).error().code, MatrixErrorCode::NoConvergence);
  LogOptions few_terms;
  few_terms.epsilon1 = 0.3;  // series from |B| ~ 0.3 needs ~17 terms for 1e-9
  EXPECT_EQ(matrix_log(a, few_terms).error().code, MatrixErrorCode::NoConvergence);
  few_terms.max_series_terms = 40;
  EXPECT_TRUE(matrix_log(a, few_terms));
}

}  // namespace
}  // namespace posefair
