#include "posefair/core/pose_spline.hpp"

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "posefair/core/euclidean_geometric_spline.hpp"
#include "posefair/core/so3_geometric_spline.hpp"
#include "posefair/core/sphere_geometric_spline.hpp"

namespace posefair::geometric_splines {
namespace {

SpherePoint<4> as_point(const Quat& q) { return q.coeffs(); }

// The S^3 tangent vector of a world angular velocity w at q: 1/2 (0, w) q.
SpherePoint<4> tangent_at(const Quat& q, const Vec3& w) {
  return 0.5 * (Quat(0.0, w.x(), w.y(), w.z()) * q).coeffs();
}

Quat orientation_at(const SmoothingFunction& phi, OrientationManifold manifold, const PoseKnot& a, const PoseKnot& b,
                    double t) {
  const double h = b.time - a.time;
  const double u = (t - a.time) / h;
  if (manifold == OrientationManifold::Sphere) {
    const SpherePoint<4> s = sphere_segment<4>(phi, as_point(a.orientation), tangent_at(a.orientation, a.angular_velocity),
                                               as_point(b.orientation), tangent_at(b.orientation, b.angular_velocity), h, u);
    return Quat(s);  // Eigen's coeffs order (x, y, z, w)
  }
  const Rotation r = so3_segment(phi, a.orientation.toRotationMatrix(), a.angular_velocity,
                                 b.orientation.toRotationMatrix(), b.angular_velocity, h, u);
  return so3::aligned_to(Quat(r), a.orientation);
}

Vec3 position_at(const SmoothingFunction& phi, const PoseKnot& a, const PoseKnot& b, double t, int order = 0) {
  const std::array<Vec3, 2> left{a.position, a.velocity};
  const std::array<Vec3, 2> right{b.position, b.velocity};
  const double h = b.time - a.time;
  return euclidean_segment<3>(phi, left, right, h, (t - a.time) / h, order);
}

// World angular velocity 2 q_dot q^-1 from a 4th-order central difference of the segment.
Vec3 segment_angular_velocity(const SmoothingFunction& phi, OrientationManifold m, const PoseKnot& a,
                              const PoseKnot& b, double t) {
  const double d = 1e-3 * (b.time - a.time);
  const Quat q = orientation_at(phi, m, a, b, t);
  auto at = [&](double s) { return so3::aligned_to(orientation_at(phi, m, a, b, s), q).coeffs(); };
  const Eigen::Vector4d qdot = (-at(t + 2 * d) + 8.0 * at(t + d) - 8.0 * at(t - d) + at(t - 2 * d)) / (12.0 * d);
  return 2.0 * (Quat(qdot) * q.conjugate()).vec();
}

}  // namespace

std::string_view to_string(OrientationManifold m) {
  return m == OrientationManifold::Sphere ? "s3" : "so3";
}

void validate(const PoseSplineOptions& options) {
  SmoothingFunction check(options.order);  // throws for a bad order
  (void)check;
  validate(options.velocity);
}

SplinePose evaluate_pose_segment(const SmoothingFunction& phi, OrientationManifold manifold, const PoseKnot& a,
                                 const PoseKnot& b, double t) {
  return {orientation_at(phi, manifold, a, b, t), position_at(phi, a, b, t)};
}

void estimate_pose_knot_velocity(KnotVelocityEstimator estimator, std::span<PoseKnot> knots, std::size_t self,
                                 bool with_position) {
  // Tangent coordinates at the knot: world rotation vectors of q_j q_i^-1, and p_j - p_i.
  std::array<double, 2 * kMaxFitHalfWidth + 1> dt{};
  std::array<Vec3, 2 * kMaxFitHalfWidth + 1> rot{};
  std::array<Vec3, 2 * kMaxFitHalfWidth + 1> pos{};
  const std::size_t n = knots.size();
  if (n > dt.size()) throw std::invalid_argument("knot velocity neighbourhood too large");
  PoseKnot& k = knots[self];
  for (std::size_t j = 0; j < n; ++j) {
    dt[j] = knots[j].time - k.time;
    rot[j] = so3::to_rotation_vector(knots[j].orientation * k.orientation.conjugate());
    pos[j] = knots[j].position - k.position;
  }
  k.angular_velocity = estimate_knot_velocity<3>(estimator, std::span(dt.data(), n), std::span<const Vec3>(rot.data(), n));
  k.velocity = with_position ? estimate_knot_velocity<3>(estimator, std::span(dt.data(), n),
                                                         std::span<const Vec3>(pos.data(), n))
                             : Vec3::Zero();
}

PoseSpline::PoseSpline(const PoseSequence& poses, const PoseSplineOptions& options)
    : with_position_(poses.has_position()), options_(options), phi_(options.order) {
  validate(options);
  const std::size_t n = poses.size();
  if (n < 2) throw std::invalid_argument("a spline needs at least 2 samples, got " + std::to_string(n));
  if (poses.time.size() != n || (with_position_ && poses.position.size() != n))
    throw std::invalid_argument("times, orientations and positions differ in length");
  std::vector<Quat> q = poses.orientation;
  so3::make_continuous(q);
  knots_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0 && !(poses.time[i] > poses.time[i - 1]))
      throw std::invalid_argument("sample " + std::to_string(i) + ": time " + std::to_string(poses.time[i]) +
                                  " does not increase on the previous sample's " + std::to_string(poses.time[i - 1]));
    knots_[i].time = poses.time[i];
    knots_[i].orientation = q[i].normalized();
    if (with_position_) knots_[i].position = poses.position[i];
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto [first, last] = knot_velocity_neighbourhood(options.velocity, i, n);
    estimate_pose_knot_velocity(options.velocity.estimator, std::span(knots_).subspan(first, last - first + 1),
                                i - first, with_position_);
  }
  times_.resize(n);
  for (std::size_t i = 0; i < n; ++i) times_[i] = knots_[i].time;
}

PoseSpline::PoseSpline(std::vector<PoseKnot> knots, bool with_position, const PoseSplineOptions& options)
    : knots_(std::move(knots)), with_position_(with_position), options_(options), phi_(options.order) {
  validate(options);
  if (knots_.size() < 2) throw std::invalid_argument("a spline needs at least 2 knots");
  for (std::size_t i = 0; i < knots_.size(); ++i) {
    if (i > 0 && !(knots_[i].time > knots_[i - 1].time))
      throw std::invalid_argument("knot " + std::to_string(i) + ": time does not increase");
    knots_[i].orientation.normalize();
    if (i > 0) knots_[i].orientation = so3::aligned_to(knots_[i].orientation, knots_[i - 1].orientation);
    times_.push_back(knots_[i].time);
  }
}

SplinePose PoseSpline::evaluate(double t) const {
  if (!(t >= start_time() && t <= end_time())) throw std::out_of_range("time outside the spline's knots");
  const std::size_t i = find_segment(times_, t);
  SplinePose p = evaluate_pose_segment(phi_, options_.manifold, knots_[i], knots_[i + 1], t);
  if (!with_position_) p.position = Vec3::Zero();
  return p;
}

Vec3 PoseSpline::angular_velocity(double t) const {
  if (!(t >= start_time() && t <= end_time())) throw std::out_of_range("time outside the spline's knots");
  const std::size_t i = find_segment(times_, t);
  return segment_angular_velocity(phi_, options_.manifold, knots_[i], knots_[i + 1], t);
}

Vec3 PoseSpline::angular_acceleration(double t) const {
  if (!(t >= start_time() && t <= end_time())) throw std::out_of_range("time outside the spline's knots");
  const std::size_t i = find_segment(times_, t);
  const PoseKnot& a = knots_[i];
  const PoseKnot& b = knots_[i + 1];
  const double d = 1e-2 * (b.time - a.time);
  auto w = [&](double s) { return segment_angular_velocity(phi_, options_.manifold, a, b, s); };
  return (-w(t + 2 * d) + 8.0 * w(t + d) - 8.0 * w(t - d) + w(t - 2 * d)) / (12.0 * d);
}

PoseSequence resample(const PoseSequence& poses, std::span<const double> times, const PoseSplineOptions& options) {
  const PoseSpline spline(poses, options);
  PoseSequence out;
  out.time.assign(times.begin(), times.end());
  out.orientation.reserve(times.size());
  if (spline.has_position()) out.position.reserve(times.size());
  for (double t : times) {
    const SplinePose p = spline.evaluate(t);
    out.orientation.push_back(p.orientation);
    if (spline.has_position()) out.position.push_back(p.position);
  }
  so3::make_continuous(out.orientation);
  return out;
}

}  // namespace posefair::geometric_splines
