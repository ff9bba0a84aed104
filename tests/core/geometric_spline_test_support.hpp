#pragma once
// Derivatives by high-order finite differences, for checking the geometric splines' boundary
// and continuity conditions where no closed-form derivative is coded.
#include <cmath>
#include <functional>

#include <Eigen/Dense>

namespace posefair::testing {

// Finite-difference step as a fraction of a segment's length (derivatives in t scale as 1/h^j).
inline constexpr double kStep = 1e-2;
// Relative tolerance for a j-th derivative by finite differences: rounding noise grows as
// 1/step^j, so each order above the second gets two digits less.
inline double fd_tolerance(int j) { return j <= 2 ? 1e-7 : 1e-7 * std::pow(100.0, j - 2); }

// Weights w_j (j = -J..J) with f^(m)(x) ~ sum_j w_j f(x + j delta) / delta^m: the m-th derivative
// at 0 of the degree-2J interpolant through the 2J+1 nodes (error O(delta^(2J+1-m))).
inline Eigen::VectorXd finite_difference_weights(int m, int half_width = 6) {
  const int n = 2 * half_width + 1;
  Eigen::MatrixXd v(n, n);  // v(r, c) = node_c^r
  for (int c = 0; c < n; ++c)
    for (int r = 0; r < n; ++r) v(r, c) = std::pow(static_cast<double>(c - half_width), r);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  double factorial = 1.0;
  for (int i = 2; i <= m; ++i) factorial *= i;
  rhs[m] = factorial;
  return v.fullPivLu().solve(rhs);
}

// d^m f / dx^m at x for a vector- or matrix-valued f.
template <typename F>
auto derivative(const F& f, double x, int m, double delta, int half_width = 6) {
  const Eigen::VectorXd w = finite_difference_weights(m, half_width);
  auto sum = (w[0] * f(x - half_width * delta)).eval();
  for (int j = 1; j < w.size(); ++j) sum += w[j] * f(x + (j - half_width) * delta);
  return (sum / std::pow(delta, m)).eval();
}

}  // namespace posefair::testing
