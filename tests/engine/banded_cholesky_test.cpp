// BandedCholesky against Eigen's dense LLT on the same matrices.
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "posefair/core/banded_cholesky.hpp"

namespace posefair {
namespace {

// A random SPD matrix with `b` sub-diagonals: L Lᵀ for a random lower band L with a diagonal
// bounded away from zero (so the test is about the algorithm, not about conditioning).
Eigen::MatrixXd random_spd_band(int n, int b, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> off(-1.0, 1.0), diag(1.0, 2.0);
  Eigen::MatrixXd l = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    l(i, i) = diag(rng);
    for (int j = std::max(0, i - b); j < i; ++j) l(i, j) = 0.5 * off(rng);
  }
  return l * l.transpose();
}

BandedCholesky to_band(const Eigen::MatrixXd& a, int b) {
  const int n = static_cast<int>(a.rows());
  BandedCholesky band(n, b);
  for (int i = 0; i < n; ++i)
    for (int j = std::max(0, i - b); j <= i; ++j) band.at(i, j) = a(i, j);
  return band;
}

Eigen::MatrixXd random_rhs(int n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  Eigen::MatrixXd r(n, 3);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) r(i, k) = u(rng);
  return r;
}

TEST(BandedCholesky, SolvesMatchADenseLLTSolve) {
  std::mt19937_64 rng(2024);
  for (int n : {1, 2, 3, 5, 17, 64, 200}) {
    for (int b : {0, 1, 2, 3, 5, 8}) {
      for (int trial = 0; trial < 3; ++trial) {
        SCOPED_TRACE("n=" + std::to_string(n) + " bandwidth=" + std::to_string(b) + " trial=" + std::to_string(trial));
        const Eigen::MatrixXd a = random_spd_band(n, b, rng);
        const Eigen::MatrixXd rhs = random_rhs(n, rng);
        const Eigen::LLT<Eigen::MatrixXd> dense(a);
        ASSERT_EQ(dense.info(), Eigen::Success);
        const Eigen::MatrixXd expected = dense.solve(rhs);

        BandedCholesky band = to_band(a, b);
        EXPECT_EQ(band.size(), n);
        EXPECT_EQ(band.bandwidth(), b);
        ASSERT_TRUE(band.factor());
        // The factor itself is Eigen's L, inside the band.
        const Eigen::MatrixXd l = dense.matrixL();
        for (int i = 0; i < n; ++i)
          for (int j = std::max(0, i - b); j <= i; ++j) ASSERT_NEAR(band.at(i, j), l(i, j), 1e-10) << i << "," << j;

        std::vector<Vec3> x(static_cast<std::size_t>(n));
        for (int i = 0; i < n; ++i) x[static_cast<std::size_t>(i)] = rhs.row(i).transpose();
        band.solve(x);
        const double scale = std::max(1.0, expected.cwiseAbs().maxCoeff());
        for (int i = 0; i < n; ++i)
          for (int k = 0; k < 3; ++k) ASSERT_NEAR(x[static_cast<std::size_t>(i)][k], expected(i, k), 1e-10 * scale) << i << "," << k;
      }
    }
  }
}

TEST(BandedCholesky, ABandwidthWiderThanTheMatrixIsADenseSolve) {
  std::mt19937_64 rng(7);
  const int n = 4, b = 6;
  const Eigen::MatrixXd a = random_spd_band(n, n - 1, rng);
  const Eigen::MatrixXd rhs = random_rhs(n, rng);
  const Eigen::MatrixXd expected = a.llt().solve(rhs);
  BandedCholesky band = to_band(a, b);
  ASSERT_TRUE(band.factor());
  std::vector<Vec3> x(n);
  for (int i = 0; i < n; ++i) x[static_cast<std::size_t>(i)] = rhs.row(i).transpose();
  band.solve(x);
  for (int i = 0; i < n; ++i) EXPECT_LT((x[static_cast<std::size_t>(i)] - expected.row(i).transpose()).norm(), 1e-10);
}

TEST(BandedCholesky, FactorReportsAMatrixThatIsNotPositiveDefinite) {
  {
    // Symmetric, indefinite: eigenvalues 3 and -1.
    BandedCholesky a(2, 1);
    a.at(0, 0) = 1.0;
    a.at(1, 0) = 2.0;
    a.at(1, 1) = 1.0;
    EXPECT_FALSE(a.factor());
  }
  {
    // A negative pivot at the end of a longer band.
    BandedCholesky a(6, 2);
    for (int i = 0; i < 6; ++i) a.at(i, i) = i == 5 ? -1.0 : 4.0;
    EXPECT_FALSE(a.factor());
  }
  {
    // Positive diagonal but singular (rank one): a zero pivot.
    BandedCholesky a(3, 2);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j <= i; ++j) a.at(i, j) = 1.0;
    EXPECT_FALSE(a.factor());
  }
  {
    BandedCholesky a(1, 0);
    a.at(0, 0) = 0.0;
    EXPECT_FALSE(a.factor());
  }
}

TEST(BandedCholesky, TheSmoothingSystemIsIdentityPlusMuDmTransposeDm) {
  for (int m : {2, 3}) {
    for (int n : {1, 2, 3, 4, 10, 33}) {
      SCOPED_TRACE("m=" + std::to_string(m) + " n=" + std::to_string(n));
      std::vector<double> d(static_cast<std::size_t>(n));
      for (int i = 0; i < n; ++i) d[static_cast<std::size_t>(i)] = 1.0 + (i % 3 == 0 ? 0.7 : 0.0);
      const double mu = 37.5;
      // Dense: diag(d) + μ (D^m)ᵀ D^m, with D^m the m-fold forward difference ((n-m)×n).
      Eigen::MatrixXd dm = Eigen::MatrixXd::Identity(n, n);
      for (int p = 0; p < m && dm.rows() > 1; ++p) {
        const auto r = dm.rows();
        dm = (dm.bottomRows(r - 1) - dm.topRows(r - 1)).eval();
      }
      Eigen::MatrixXd a = Eigen::MatrixXd(Eigen::VectorXd::Map(d.data(), n).asDiagonal());
      if (n > m) a += mu * dm.transpose() * dm;
      std::mt19937_64 rng(static_cast<std::uint64_t>(n * 10 + m));
      const Eigen::MatrixXd rhs = random_rhs(n, rng);
      const Eigen::MatrixXd expected = a.llt().solve(rhs);
      const BandedCholesky band = make_smoothing_system(n, m, mu, d);
      EXPECT_EQ(band.bandwidth(), m);
      std::vector<Vec3> x(static_cast<std::size_t>(n));
      for (int i = 0; i < n; ++i) x[static_cast<std::size_t>(i)] = rhs.row(i).transpose();
      band.solve(x);
      for (int i = 0; i < n; ++i) EXPECT_LT((x[static_cast<std::size_t>(i)] - expected.row(i).transpose()).norm(), 1e-10) << i;
    }
  }
}

TEST(BandedCholesky, ASmoothingSystemWithoutADataTermIsAnError) {
  std::vector<double> d(5, 0.0);
  EXPECT_THROW(make_smoothing_system(5, 2, 0.0, d), std::invalid_argument);
  // A negative data weight that the smoothness term cannot make up for: e₂ᵀAe₂ = -5 + 0.6.
  const std::vector<double> negative = {1.0, 1.0, -5.0, 1.0, 1.0};
  EXPECT_THROW(make_smoothing_system(5, 2, 0.1, negative), std::invalid_argument);
  EXPECT_NO_THROW(make_smoothing_system(5, 2, 0.1, std::vector<double>(5, 1.0)));
}

}  // namespace
}  // namespace posefair
