#include "posefair/core/so3_geometric_spline.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "posefair/core/euclidean_geometric_spline.hpp"
#include "posefair/core/sphere_geometric_spline.hpp"

namespace posefair::geometric_splines {
namespace {

Eigen::Matrix3d hat(const Vec3& w) {
  Eigen::Matrix3d k;
  k << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  return k;
}

}  // namespace

Rotation rotation_exp(const Vec3& w) {
  // I + sinc(theta) K + (1 - cos theta)/theta^2 K^2, with (1 - cos theta)/theta^2 = sinc(theta/2)^2 / 2.
  const double theta = w.norm();
  const Eigen::Matrix3d k = hat(w);
  const double half = sinc(0.5 * theta);
  return Eigen::Matrix3d::Identity() + sinc(theta) * k + (0.5 * half * half) * (k * k);
}

Vec3 rotation_log(const Rotation& r) {
  // Through the quaternion (Eigen's branch-safe conversion) and so3::log (half-angle).
  return so3::to_rotation_vector(Quat(r));
}

Rotation so3_segment(const SmoothingFunction& phi, const Rotation& p0, const Vec3& w0, const Rotation& p1,
                     const Vec3& w1, double h, double u) {
  const Rotation l = rotation_exp(u * h * w0) * p0;
  const Rotation c = rotation_exp(u * rotation_log(p1 * p0.transpose())) * p0;
  const Rotation r = rotation_exp((u - 1.0) * h * w1) * p1;
  const double f = phi(u);
  const Rotation a = rotation_exp(f * rotation_log(c * l.transpose())) * l;
  const Rotation b = rotation_exp(f * rotation_log(r * c.transpose())) * c;
  return rotation_exp(f * rotation_log(b * a.transpose())) * a;
}

So3GeometricSpline::So3GeometricSpline(std::vector<double> times, std::vector<Rotation> rotations,
                                       std::vector<Vec3> angular_velocities, int order)
    : times_(std::move(times)),
      rotations_(std::move(rotations)),
      angular_velocities_(std::move(angular_velocities)),
      phi_(order) {
  if (times_.size() != rotations_.size() || times_.size() != angular_velocities_.size())
    throw std::invalid_argument("times, rotations and angular velocities differ in length");
  if (times_.size() < 2) throw std::invalid_argument("a spline needs at least 2 knots");
  for (std::size_t i = 1; i < times_.size(); ++i)
    if (!(times_[i] > times_[i - 1]))
      throw std::invalid_argument("knot " + std::to_string(i) + ": time does not increase");
}

Rotation So3GeometricSpline::evaluate_segment(std::size_t i, double t) const {
  const double h = times_.at(i + 1) - times_[i];
  return so3_segment(phi_, rotations_[i], angular_velocities_[i], rotations_[i + 1], angular_velocities_[i + 1], h,
                     (t - times_[i]) / h);
}

Rotation So3GeometricSpline::evaluate(double t) const {
  if (!(t >= start_time() && t <= end_time())) throw std::out_of_range("time outside the spline's knots");
  return evaluate_segment(find_segment(times_, t), t);
}

}  // namespace posefair::geometric_splines
