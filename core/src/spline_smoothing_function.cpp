#include "posefair/core/spline_smoothing_function.hpp"

#include <array>
#include <stdexcept>
#include <string>

namespace posefair::geometric_splines {

double polynomial_derivative(const double* c, int n, double u, int j) {
  // Horner over the j-times differentiated coefficients c[m] * m! / (m - j)!.
  double value = 0.0;
  for (int m = n - 1; m >= j; --m) {
    double falling = 1.0;
    for (int f = 0; f < j; ++f) falling *= m - f;
    value = value * u + c[m] * falling;
  }
  return value;
}

SmoothingFunction::SmoothingFunction(int k) : k_(k) {
  if (k < 1 || k > kMaxSplineOrder)
    throw std::invalid_argument("spline order k must be in 1.." + std::to_string(kMaxSplineOrder) + ", got " +
                                std::to_string(k));
  // Eq. 9: alpha_{k+l} = (-1)^l C(k-1, l); gamma normalises phi(1) to 1.
  double inverse_gamma = 0.0;
  for (int l = 0; l < k; ++l) {
    const double a = ((l % 2) ? -1.0 : 1.0) * binomial(k - 1, l) / (k + l);
    phi_[k + l] = a;
    inverse_gamma += a;
  }
  phi_ /= inverse_gamma;
}

double SmoothingFunction::near_zero(double u, int j) const { return polynomial_derivative(phi_.data(), 2 * k_, u, j); }

double SmoothingFunction::derivative(double u, int j) const {
  if (u <= 0.5) return near_zero(u, j);
  // phi(u) = 1 - phi(1 - u), so phi^(j)(u) = (-1)^(j+1) phi^(j)(1 - u) for j >= 1.
  if (j == 0) return 1.0 - near_zero(1.0 - u, 0);
  return ((j % 2) ? 1.0 : -1.0) * near_zero(1.0 - u, j);
}

Eigen::Vector3d SmoothingFunction::blend_weights(double u, int j) const {
  if (j > 4 * k_ - 2) return Eigen::Vector3d::Zero();  // beyond the weights' degree
  // Leibniz on (1-phi)^2, 2 phi (1-phi), phi^2, with 1 - phi taken from the accurate side.
  std::array<double, 4 * kMaxSplineOrder> f{}, g{};
  for (int m = 0; m <= j; ++m) {
    f[m] = derivative(u, m);
    g[m] = -f[m];
  }
  g[0] = u <= 0.5 ? 1.0 - near_zero(u, 0) : near_zero(1.0 - u, 0);
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  double binom = 1.0;  // C(j, m)
  for (int m = 0; m <= j; ++m) {
    w[0] += binom * g[m] * g[j - m];
    w[1] += 2.0 * binom * f[m] * g[j - m];
    w[2] += binom * f[m] * f[j - m];
    binom = binom * (j - m) / (m + 1);
  }
  return w;
}

}  // namespace posefair::geometric_splines
