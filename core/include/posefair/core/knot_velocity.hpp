#pragma once
// Knot velocities estimated from the data when none are given. Every estimator works in the
// tangent space at the knot: the caller supplies x_j = log_{p_i}(p_j) for the neighbours j
// (x_i = 0; in R^n simply p_j - p_i), and gets the velocity as the slope at t_i of
//   CentralDifference : the chord through the two outer neighbours, (x_{i+1} - x_{i-1}) /
//                       (t_{i+1} - t_{i-1}) (Catmull-Rom on non-uniform knots); one-sided at the ends;
//   Bessel            : the parabola through x_{i-1}, x_i, x_{i+1} (second-order accurate on
//                       non-uniform knots; equals CentralDifference on uniform ones); at the ends
//                       the parabola through the first or last three knots;
//   LocalQuadraticFit : the least-squares parabola through the 2w+1 knots i-w .. i+w (shifted to
//                       stay inside the data at the ends); smooths measurement noise.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <string_view>
#include <utility>

#include <Eigen/Core>
#include <Eigen/Cholesky>

namespace posefair::geometric_splines {

enum class KnotVelocityEstimator { CentralDifference, Bessel, LocalQuadraticFit };

std::string_view to_string(KnotVelocityEstimator e);

inline constexpr int kMaxFitHalfWidth = 16;

struct KnotVelocityOptions {
  KnotVelocityEstimator estimator = KnotVelocityEstimator::Bessel;
  int fit_half_width = 3;  // LocalQuadraticFit: w, 1 .. kMaxFitHalfWidth
};

// Throws std::invalid_argument for a half width outside 1 .. kMaxFitHalfWidth.
void validate(const KnotVelocityOptions& options);

// The knots [first, last] the estimate at knot i uses among knots 0 .. count-1 (count >= 2).
// Pass count = SIZE_MAX for a stream whose end is not known yet (no clipping on the right).
std::pair<std::size_t, std::size_t> knot_velocity_neighbourhood(const KnotVelocityOptions& options, std::size_t i,
                                                                std::size_t count);

// The slope at dt = 0 given the neighbours' time offsets dt[j] = t_j - t_i and tangent
// coordinates x[j] (both in neighbourhood order, one of them the knot itself with dt = 0).
template <int N>
Eigen::Matrix<double, N, 1> estimate_knot_velocity(KnotVelocityEstimator estimator, std::span<const double> dt,
                                                   std::span<const Eigen::Matrix<double, N, 1>> x) {
  using V = Eigen::Matrix<double, N, 1>;
  const std::size_t n = dt.size();
  if (estimator == KnotVelocityEstimator::CentralDifference || n == 2)
    return (x[n - 1] - x[0]) / (dt[n - 1] - dt[0]);
  // Least-squares parabola x(tau) = c0 + c1 tau + c2 tau^2 with tau = dt / scale (for
  // conditioning); with 3 points it interpolates (Bessel). Normal equations, fixed size.
  double scale = 0.0;
  for (double d : dt) scale = std::max(scale, std::abs(d));
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 3, N> atx = Eigen::Matrix<double, 3, N>::Zero(3, x[0].size());
  for (std::size_t j = 0; j < n; ++j) {
    const double tau = dt[j] / scale;
    const Eigen::Vector3d row(1.0, tau, tau * tau);
    ata += row * row.transpose();
    atx += row * x[j].transpose();
  }
  const Eigen::Matrix<double, 3, N> c = ata.ldlt().solve(atx);
  return V(c.row(1).transpose()) / scale;
}

}  // namespace posefair::geometric_splines
