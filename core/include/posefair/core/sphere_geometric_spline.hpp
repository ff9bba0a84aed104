#pragma once
// The three-step algorithm on the unit sphere S^{D-1} in R^D (Rodrigues, Silva Leite &
// Jakubiak, Section 4.2): geodesics through a point with a velocity (eq. 20) for the left and
// right components, great arcs (eq. 21) for the center component and for Steps 2 and 3
// (eq. 22), blended with the smoothing function phi of eq. 9. D = 3: directions on S^2;
// D = 4: unit quaternions on S^3 (as 4-vectors; the metric is the round one).
// On [t_i, t_{i+1}] with u = (t - t_i) / h, velocities per second are scaled by h (ERRATA 4).
// The paper proves C^2 (Theorem 4.3) for every phi satisfying eq. 4; the tests also check
// C^k for phi of order k (the segment agrees with its end geodesics to order k).
#include <span>
#include <vector>

#include <Eigen/Core>

#include "posefair/core/spline_smoothing_function.hpp"

namespace posefair::geometric_splines {

template <int D>
using SpherePoint = Eigen::Matrix<double, D, 1>;

// sin(x) / x, accurate through x -> 0.
double sinc(double x);

// Eq. 20: the geodesic through p (unit) with tangent velocity v, at parameter tau.
template <int D>
SpherePoint<D> sphere_geodesic(const SpherePoint<D>& p, const SpherePoint<D>& v, double tau);

// Eq. 21: the great arc from y0 to y1 (unit, not antipodal) at fraction s; theta is computed as
// 2 atan2(|y1 - y0|, |y1 + y0|) so that it stays accurate for nearby points.
template <int D>
SpherePoint<D> sphere_arc(const SpherePoint<D>& y0, const SpherePoint<D>& y1, double s);

// The Riemannian logarithm: the tangent vector at p (unit) pointing to q with length the angle.
template <int D>
SpherePoint<D> sphere_log(const SpherePoint<D>& p, const SpherePoint<D>& q);

// v minus its component along p: the tangent part (ERRATA item 3: project given velocities).
template <int D>
SpherePoint<D> project_to_tangent(const SpherePoint<D>& p, const SpherePoint<D>& v) {
  return v - p.dot(v) * p;
}

// Eq. 22 on one segment: points p0, p1 (unit), tangent velocities v0, v1 per second, knot
// spacing h, at u (any real u near [0, 1]; the formula continues smoothly). The velocities are
// used as given (project them first). Intermediate points must not become antipodal, which
// holds whenever h|v| and the knot distance are well below pi/2.
template <int D>
SpherePoint<D> sphere_segment(const SmoothingFunction& phi, const SpherePoint<D>& p0, const SpherePoint<D>& v0,
                              const SpherePoint<D>& p1, const SpherePoint<D>& v1, double h, double u);

template <int D>
class SphereGeometricSpline {
 public:
  // Points are normalised, velocities projected onto the tangent space at their point.
  // Throws std::invalid_argument: sizes differ, fewer than 2 knots, times not strictly
  // increasing, a zero point.
  SphereGeometricSpline(std::vector<double> times, std::vector<SpherePoint<D>> points,
                        std::vector<SpherePoint<D>> velocities, int order);

  double start_time() const { return times_.front(); }
  double end_time() const { return times_.back(); }
  const std::vector<double>& times() const { return times_; }
  const std::vector<SpherePoint<D>>& points() const { return points_; }
  const std::vector<SpherePoint<D>>& velocities() const { return velocities_; }

  // Inside [start_time, end_time], else std::out_of_range.
  SpherePoint<D> evaluate(double t) const;
  // Segment i's formula at t (which may lie slightly outside the segment).
  SpherePoint<D> evaluate_segment(std::size_t i, double t) const;

 private:
  std::vector<double> times_;
  std::vector<SpherePoint<D>> points_;
  std::vector<SpherePoint<D>> velocities_;
  SmoothingFunction phi_;
};

extern template class SphereGeometricSpline<3>;
extern template class SphereGeometricSpline<4>;

}  // namespace posefair::geometric_splines
