#pragma once
// The three-step algorithm of Rodrigues, Silva Leite & Jakubiak in R^n (Section 3), with the
// uneven conditions of Corollary 3.1: knot i prescribes its value and its first k_i time
// derivatives (1 <= k_i <= k). On the segment [t_i, t_{i+1}], u = (t - t_i) / h, h = t_{i+1} - t_i:
//   l(u) = sum_{j<=k_i} p_i^(j) h^j u^j / j!          (eq. 12; a derivative per second of order j
//   r(u) = sum_{j<=k_{i+1}} p_{i+1}^(j) h^j (u-1)^j / j!   scales by h^j on [0, 1], ERRATA item 4)
//   c(u) = p_i + u (p_{i+1} - p_i)                     (eq. 2)
//   s(u) = (1-phi)^2 l + 2 phi (1-phi) c + phi^2 r    (eq. 6, phi of eq. 9)
// The spline is C^k; at every knot s^(j) = p^(j) for j <= k_i and s^(j) = 0 for k_i < j <= k.
#include <span>
#include <vector>

#include <Eigen/Core>

#include "posefair/core/spline_smoothing_function.hpp"

namespace posefair::geometric_splines {

template <int N>
using Vector = Eigen::Matrix<double, N, 1>;

// d^order s / dt^order at t = t_i + u h of the segment between two knots, where left[j] and
// right[j] are the j-th time derivatives (per second) prescribed at t_i and t_{i+1}
// (left[0], right[0] the values). Valid for any real u (the segment is a polynomial).
// Requires 1 <= left.size() - 1 <= phi.order() (same for right), h > 0.
template <int N>
Vector<N> euclidean_segment(const SmoothingFunction& phi, std::span<const Vector<N>> left,
                            std::span<const Vector<N>> right, double h, double u, int order = 0);

// Conditions at one knot: time and value plus derivatives, derivative[0] = value.
template <int N>
struct EuclideanKnot {
  double time = 0.0;
  std::vector<Vector<N>> derivative;
};

// A whole spline through knots with strictly increasing times.
template <int N>
class EuclideanGeometricSpline {
 public:
  // Throws std::invalid_argument: fewer than 2 knots, times not strictly increasing, a knot
  // with no velocity or more than k derivatives, mixed dimensions.
  EuclideanGeometricSpline(std::vector<EuclideanKnot<N>> knots, int order);

  double start_time() const { return knots_.front().time; }
  double end_time() const { return knots_.back().time; }
  int order() const { return phi_.order(); }
  const std::vector<EuclideanKnot<N>>& knots() const { return knots_; }

  // d^derivative s / dt^derivative at t in [start_time, end_time] (throws std::out_of_range
  // outside). At a knot the segment on its right is used (the left one agrees up to order k).
  Vector<N> evaluate(double t, int derivative = 0) const;
  // The same on segment i explicitly (t may lie outside it: the polynomial continues).
  Vector<N> evaluate_segment(std::size_t i, double t, int derivative = 0) const;
  // The segment holding t (the last one for t == end_time).
  std::size_t segment_index(double t) const;

 private:
  std::vector<EuclideanKnot<N>> knots_;
  SmoothingFunction phi_;
};

extern template class EuclideanGeometricSpline<Eigen::Dynamic>;
extern template class EuclideanGeometricSpline<3>;

// Index i with times[i] <= t < times[i+1] (the last segment for t == times.back()).
// times strictly increasing, size >= 2, t inside the range.
std::size_t find_segment(std::span<const double> times, double t);

}  // namespace posefair::geometric_splines
