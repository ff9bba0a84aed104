// The Section 4.2 and 5.1 studies on small samples: what the doc's numbers rest on.
#include <cmath>
#include <map>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "posefair/core/matrix_interpolation_study.hpp"

namespace posefair {
namespace {

TEST(Section42, SquareRootConvergesWithinTenIterationsWhenAPrincipalRootExists) {
  const auto rows = sqrt_iteration_study(40, 12, 7);
  std::map<int, int> first_below;  // matrix -> first iteration with residual < 1e-6
  std::map<int, bool> principal;
  for (const auto& r : rows) {
    principal[r.matrix] = r.principal;
    if (r.residual < 1e-6 && !first_below.count(r.matrix)) first_below[r.matrix] = r.iteration;
  }
  int with_root = 0;
  for (const auto& [m, p] : principal) {
    if (!p) {
      EXPECT_FALSE(first_below.count(m)) << "matrix " << m << " has no principal root but converged";
      continue;
    }
    ++with_root;
    ASSERT_TRUE(first_below.count(m)) << "matrix " << m;
    EXPECT_LE(first_below[m], 10);
  }
  EXPECT_GT(with_root, 10);
}

TEST(Section42, TooManySquareRootsLosePrecisionWithEps3OfTheIteration) {
  const auto rows = log_square_root_study(10, 30, 1e-6, false, 11);
  ASSERT_FALSE(rows.empty());
  double best = 1e300, at_30 = 0.0;
  for (const auto& r : rows) {
    if (std::isfinite(r.error)) best = std::min(best, r.error);
    if (r.square_roots == 30 && std::isfinite(r.error)) at_30 = std::max(at_30, r.error);
  }
  EXPECT_LT(best, 1e-8);
  EXPECT_GT(at_30, 1e3 * best);  // 30 roots: far worse than the best count
}

TEST(Section42, LargeRotationsFailOnlyWhereThereIsNoPrincipalLogarithm) {
  const auto s = large_rotation_study(200, 5);
  EXPECT_GT(s.negative_eigenvalue, 0);
  EXPECT_EQ(s.sqrt_failed_without_negative, 0);
  EXPECT_LT(s.worst_log_error, 2e-3);  // the paper's constants (see MatrixLog tests)
}

TEST(Section51, MatrixInterpolationMovesVerticesLessThanParameterInterpolation) {
  const auto s = path_length_study(20, 3);
  ASSERT_EQ(s.pairs.size(), 20u);
  EXPECT_LT(s.mean_matrix, s.mean_parameter);
  EXPECT_LT(s.median_matrix, s.median_parameter);
}

}  // namespace
}  // namespace posefair
