#pragma once
// Binomial coefficients and factorials as doubles, for the small orders of difference stencils,
// spline bases and polynomial fits (n well below 30, where every value is exact in a double).

namespace posefair {

// C(n, k), built up as C(n-k+j, j) so every intermediate is an integer.
constexpr double binomial(int n, int k) {
  double b = 1.0;
  for (int j = 1; j <= k; ++j) b = b * (n - k + j) / j;
  return b;
}

constexpr double factorial(int n) {
  double f = 1.0;
  for (int i = 2; i <= n; ++i) f *= i;
  return f;
}

}  // namespace posefair
