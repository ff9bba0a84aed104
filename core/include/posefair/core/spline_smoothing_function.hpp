#pragma once
// The smoothing function phi of Rodrigues, Silva Leite & Jakubiak (eq. 9) and the three blend
// weights of their Step 3 (eq. 6), all polynomials in the segment parameter u in [0, 1]:
//   phi(u) = gamma * sum_{l=0}^{k-1} (-1)^l C(k-1, l) u^{k+l} / (k+l),  1/gamma = sum of the same at u = 1
//   w_left = (1 - phi)^2,  w_center = 2 phi (1 - phi),  w_right = phi^2.
// phi(0) = 0, phi(1) = 1 and its derivatives 1 .. k-1 vanish at both ends (eq. 4); it is the
// antiderivative of gamma u^{k-1} (1-u)^{k-1}. Near u = 1 it is evaluated through the symmetry
// phi(u) = 1 - phi(1 - u), so the end conditions hold to rounding at both ends. k = 1: phi = u; k = 2: u^2 (3 - 2u) (ERRATA
// item 1: the OCR dropped the minus sign); k = 3: u^3 (10 - 15u + 6u^2).
#include <Eigen/Core>

#include "posefair/core/combinatorics.hpp"

namespace posefair::geometric_splines {

// Highest supported smoothness order k (phi has degree 2k-1, the weights 4k-2).
inline constexpr int kMaxSplineOrder = 8;

using posefair::binomial;  // phi's and Leibniz's coefficients (combinatorics.hpp)

class SmoothingFunction {
 public:
  // k >= 1 and <= kMaxSplineOrder; throws std::invalid_argument otherwise.
  explicit SmoothingFunction(int k);

  int order() const { return k_; }
  // d^j phi / du^j at u (j >= 0). Defined for every real u (a polynomial).
  double derivative(double u, int j = 0) const;
  double operator()(double u) const { return derivative(u, 0); }
  // (w_left, w_center, w_right) differentiated j times at u.
  Eigen::Vector3d blend_weights(double u, int j = 0) const;

  // Coefficients in ascending powers of u (degree 2k-1).
  Eigen::VectorXd coefficients() const { return phi_.head(2 * k_).eval(); }

 private:
  static constexpr int kMaxCoefficients = 2 * kMaxSplineOrder;
  using Coefficients = Eigen::Matrix<double, kMaxCoefficients, 1>;
  // phi^(j)(u) from the monomial coefficients, accurate near u = 0.
  double near_zero(double u, int j) const;
  int k_;
  Coefficients phi_ = Coefficients::Zero();
};

// The j-th derivative at u of the polynomial with coefficients c[0..n-1] (ascending powers).
double polynomial_derivative(const double* c, int n, double u, int j);

}  // namespace posefair::geometric_splines
