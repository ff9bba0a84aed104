#include "posefair/core/sphere_geometric_spline.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "posefair/core/euclidean_geometric_spline.hpp"

namespace posefair::geometric_splines {

double sinc(double x) {
  const double x2 = x * x;
  // Taylor to x^6 below 1e-3 (error < 1e-21); sin(x)/x above.
  if (std::abs(x) < 1e-3) return 1.0 - x2 / 6.0 * (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0));
  return std::sin(x) / x;
}

template <int D>
SpherePoint<D> sphere_geodesic(const SpherePoint<D>& p, const SpherePoint<D>& v, double tau) {
  // cos(tau |v|) p + sin(tau |v|) v / |v|, written with sinc so |v| -> 0 is exact.
  const double a = tau * v.norm();
  return std::cos(a) * p + (tau * sinc(a)) * v;
}

template <int D>
SpherePoint<D> sphere_arc(const SpherePoint<D>& y0, const SpherePoint<D>& y1, double s) {
  const double theta = 2.0 * std::atan2((y1 - y0).norm(), (y1 + y0).norm());
  // sin((1-s) theta) / sin(theta) = (1-s) sinc((1-s) theta) / sinc(theta), likewise for s.
  const double st = sinc(theta);
  return ((1.0 - s) * sinc((1.0 - s) * theta) / st) * y0 + (s * sinc(s * theta) / st) * y1;
}

template <int D>
SpherePoint<D> sphere_log(const SpherePoint<D>& p, const SpherePoint<D>& q) {
  const SpherePoint<D> w = q - p.dot(q) * p;
  const double theta = 2.0 * std::atan2((q - p).norm(), (q + p).norm());
  const double n = w.norm();
  if (n == 0.0) return SpherePoint<D>::Zero();
  return (theta / n) * w;
}

template <int D>
SpherePoint<D> sphere_segment(const SmoothingFunction& phi, const SpherePoint<D>& p0, const SpherePoint<D>& v0,
                              const SpherePoint<D>& p1, const SpherePoint<D>& v1, double h, double u) {
  // Step 1: left and right geodesics (eq. 20), center arc (eq. 21).
  const SpherePoint<D> l = sphere_geodesic<D>(p0, h * v0, u);
  const SpherePoint<D> r = sphere_geodesic<D>(p1, h * v1, u - 1.0);
  const SpherePoint<D> c = sphere_arc<D>(p0, p1, u);
  // Steps 2 and 3: great-arc blends at fraction phi(u).
  const double f = phi(u);
  const SpherePoint<D> a = sphere_arc<D>(l, c, f);
  const SpherePoint<D> b = sphere_arc<D>(c, r, f);
  return sphere_arc<D>(a, b, f);
}

template <int D>
SphereGeometricSpline<D>::SphereGeometricSpline(std::vector<double> times, std::vector<SpherePoint<D>> points,
                                                std::vector<SpherePoint<D>> velocities, int order)
    : times_(std::move(times)), points_(std::move(points)), velocities_(std::move(velocities)), phi_(order) {
  if (times_.size() != points_.size() || times_.size() != velocities_.size())
    throw std::invalid_argument("times, points and velocities differ in length");
  if (times_.size() < 2) throw std::invalid_argument("a spline needs at least 2 knots");
  for (std::size_t i = 0; i < times_.size(); ++i) {
    if (i > 0 && !(times_[i] > times_[i - 1]))
      throw std::invalid_argument("knot " + std::to_string(i) + ": time does not increase");
    const double n = points_[i].norm();
    if (!(n > 0.0)) throw std::invalid_argument("knot " + std::to_string(i) + ": zero point");
    points_[i] /= n;
    velocities_[i] = project_to_tangent<D>(points_[i], velocities_[i]);
  }
}

template <int D>
SpherePoint<D> SphereGeometricSpline<D>::evaluate_segment(std::size_t i, double t) const {
  const double h = times_.at(i + 1) - times_[i];
  return sphere_segment<D>(phi_, points_[i], velocities_[i], points_[i + 1], velocities_[i + 1], h,
                           (t - times_[i]) / h);
}

template <int D>
SpherePoint<D> SphereGeometricSpline<D>::evaluate(double t) const {
  if (!(t >= start_time() && t <= end_time())) throw std::out_of_range("time outside the spline's knots");
  return evaluate_segment(find_segment(times_, t), t);
}

#define POSEFAIR_SPHERE_INSTANCES(D)                                                                         \
  template SpherePoint<D> sphere_geodesic<D>(const SpherePoint<D>&, const SpherePoint<D>&, double);         \
  template SpherePoint<D> sphere_arc<D>(const SpherePoint<D>&, const SpherePoint<D>&, double);              \
  template SpherePoint<D> sphere_log<D>(const SpherePoint<D>&, const SpherePoint<D>&);                      \
  template SpherePoint<D> sphere_segment<D>(const SmoothingFunction&, const SpherePoint<D>&,                 \
                                            const SpherePoint<D>&, const SpherePoint<D>&,                   \
                                            const SpherePoint<D>&, double, double);                         \
  template class SphereGeometricSpline<D>;
POSEFAIR_SPHERE_INSTANCES(3)
POSEFAIR_SPHERE_INSTANCES(4)
#undef POSEFAIR_SPHERE_INSTANCES

}  // namespace posefair::geometric_splines
