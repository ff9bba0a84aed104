#include "posefair/core/euclidean_geometric_spline.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace posefair::geometric_splines {
namespace {

// q-th u-derivative of the Taylor component sum_j d[j] h^j (u - u0)^j / j!.
template <int N>
Vector<N> taylor_component(std::span<const Vector<N>> d, double h, double x, int q) {
  Vector<N> sum = Vector<N>::Zero(d[0].size());
  double h_power = 1.0;
  for (int j = 0; j < q && j < static_cast<int>(d.size()); ++j) h_power *= h;
  // d^q/du^q of h^j x^j / j! = h^j x^(j-q) / (j-q)!.
  for (int j = q; j < static_cast<int>(d.size()); ++j) {
    double term = h_power;
    for (int m = 1; m <= j - q; ++m) term *= x / m;
    sum += term * d[j];
    h_power *= h;
  }
  return sum;
}

}  // namespace

std::size_t find_segment(std::span<const double> times, double t) {
  const auto it = std::upper_bound(times.begin(), times.end(), t);
  const auto i = static_cast<std::size_t>(std::max<std::ptrdiff_t>(1, it - times.begin()) - 1);
  return std::min(i, times.size() - 2);
}

template <int N>
Vector<N> euclidean_segment(const SmoothingFunction& phi, std::span<const Vector<N>> left,
                            std::span<const Vector<N>> right, double h, double u, int order) {
  // Leibniz: s^(m) = sum_q C(m, q) [w_l^(m-q) l^(q) + w_c^(m-q) c^(q) + w_r^(m-q) r^(q)].
  Vector<N> s = Vector<N>::Zero(left[0].size());
  for (int q = 0; q <= order; ++q) {
    const Eigen::Vector3d w = phi.blend_weights(u, order - q);
    const double c = binomial(order, q);
    const Vector<N> l_q = taylor_component<N>(left, h, u, q);
    const Vector<N> r_q = taylor_component<N>(right, h, u - 1.0, q);
    Vector<N> c_q;
    if (q == 0)
      c_q = left[0] + u * (right[0] - left[0]);
    else if (q == 1)
      c_q = right[0] - left[0];
    else
      c_q = Vector<N>::Zero(left[0].size());
    s += c * (w[0] * l_q + w[1] * c_q + w[2] * r_q);
  }
  // Chain rule for u = (t - t_i) / h.
  double scale = 1.0;
  for (int j = 0; j < order; ++j) scale /= h;
  return scale * s;
}

template <int N>
EuclideanGeometricSpline<N>::EuclideanGeometricSpline(std::vector<EuclideanKnot<N>> knots, int order)
    : knots_(std::move(knots)), phi_(order) {
  if (knots_.size() < 2) throw std::invalid_argument("a spline needs at least 2 knots");
  const auto dim = knots_[0].derivative.empty() ? 0 : knots_[0].derivative[0].size();
  for (std::size_t i = 0; i < knots_.size(); ++i) {
    const auto& k = knots_[i];
    const std::string where = "knot " + std::to_string(i) + ": ";
    if (k.derivative.size() < 2)
      throw std::invalid_argument(where + "needs a value and at least a velocity");
    if (static_cast<int>(k.derivative.size()) - 1 > order)
      throw std::invalid_argument(where + "prescribes " + std::to_string(k.derivative.size() - 1) +
                                  " derivatives, more than the order k = " + std::to_string(order) +
                                  " (Corollary 3.1 needs k_i <= k)");
    for (const auto& d : k.derivative)
      if (d.size() != dim) throw std::invalid_argument(where + "dimension differs from knot 0");
    if (i > 0 && !(k.time > knots_[i - 1].time))
      throw std::invalid_argument(where + "time does not increase");
    times_.push_back(k.time);
  }
}

template <int N>
std::size_t EuclideanGeometricSpline<N>::segment_index(double t) const {
  return find_segment(times_, t);
}

template <int N>
Vector<N> EuclideanGeometricSpline<N>::evaluate_segment(std::size_t i, double t, int derivative) const {
  const auto& a = knots_.at(i);
  const auto& b = knots_.at(i + 1);
  const double h = b.time - a.time;
  return euclidean_segment<N>(phi_, a.derivative, b.derivative, h, (t - a.time) / h, derivative);
}

template <int N>
Vector<N> EuclideanGeometricSpline<N>::evaluate(double t, int derivative) const {
  if (!(t >= start_time() && t <= end_time())) throw std::out_of_range("time outside the spline's knots");
  return evaluate_segment(segment_index(t), t, derivative);
}

template class EuclideanGeometricSpline<Eigen::Dynamic>;
template class EuclideanGeometricSpline<3>;
template Vector<Eigen::Dynamic> euclidean_segment<Eigen::Dynamic>(const SmoothingFunction&,
                                                                  std::span<const Vector<Eigen::Dynamic>>,
                                                                  std::span<const Vector<Eigen::Dynamic>>, double,
                                                                  double, int);
template Vector<3> euclidean_segment<3>(const SmoothingFunction&, std::span<const Vector<3>>,
                                        std::span<const Vector<3>>, double, double, int);

}  // namespace posefair::geometric_splines
