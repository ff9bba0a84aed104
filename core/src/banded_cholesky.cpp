#include "posefair/core/banded_cholesky.hpp"

#include "posefair/core/combinatorics.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace posefair {

BandedCholesky::BandedCholesky(int n, int bandwidth)
    : n_(n), b_(bandwidth), band_(static_cast<std::size_t>(n * (bandwidth + 1)), 0.0) {}

bool BandedCholesky::factor() {
  for (int i = 0; i < n_; ++i) {
    for (int k = std::max(0, i - b_); k <= i; ++k) {
      double s = at(i, k);
      for (int j = std::max(0, i - b_); j < k; ++j)
        if (k - j <= b_) s -= at(i, j) * at(k, j);
      if (k == i) {
        if (!(s > 0.0)) return false;
        at(i, i) = std::sqrt(s);
      } else {
        at(i, k) = s / at(k, k);
      }
    }
  }
  return true;
}

void BandedCholesky::solve(std::span<Vec3> x) const {
  // L y = rhs, then Lᵀ x = y.
  for (int i = 0; i < n_; ++i) {
    Vec3 s = x[static_cast<std::size_t>(i)];
    for (int j = std::max(0, i - b_); j < i; ++j) s -= at(i, j) * x[static_cast<std::size_t>(j)];
    x[static_cast<std::size_t>(i)] = s / at(i, i);
  }
  for (int i = n_ - 1; i >= 0; --i) {
    Vec3 s = x[static_cast<std::size_t>(i)];
    for (int j = i + 1; j <= std::min(n_ - 1, i + b_); ++j) s -= at(j, i) * x[static_cast<std::size_t>(j)];
    x[static_cast<std::size_t>(i)] = s / at(i, i);
  }
}

void BandedCholesky::reshape(int n) {
  n_ = n;
  std::fill(band_.begin(), band_.begin() + static_cast<std::ptrdiff_t>(n * (b_ + 1)), 0.0);
}

bool assemble_smoothing_system(BandedCholesky& a, int n, int m, double mu, std::span<const double> diagonal) {
  a.reshape(n);
  for (int i = 0; i < n; ++i) a.at(i, i) = diagonal[static_cast<std::size_t>(i)];
  if (n > m && mu > 0.0) {
    // Stencil of D^m: (-1)^(m-k) C(m, k), k = 0..m (m ≤ 3 here; at most 8 entries in any case).
    double c[9] = {};
    for (int k = 0; k <= m && k < 9; ++k) {
      c[k] = ((m - k) % 2 == 0 ? 1.0 : -1.0) * binomial(m, k);
    }
    for (int row = 0; row + m < n; ++row)
      for (int k = 0; k <= m; ++k)
        for (int l = 0; l <= k; ++l) a.at(row + k, row + l) += mu * c[k] * c[l];
  }
  return a.factor();
}

BandedCholesky make_smoothing_system(int n, int m, double mu, std::span<const double> diagonal) {
  BandedCholesky a(n, m);
  if (!assemble_smoothing_system(a, n, m, mu, diagonal)) throw std::invalid_argument("smoothing system is not positive definite");
  return a;
}

}  // namespace posefair
