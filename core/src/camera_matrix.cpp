#include "posefair/core/camera_matrix.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <Eigen/Geometry>

namespace posefair {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// Z-Y-X Euler angles (yaw, pitch, roll) of an orientation o = Rz(yaw) Ry(pitch) Rx(roll).
Vector3d euler_zyx(const Matrix3d& o) {
  return {std::atan2(o(1, 0), o(0, 0)), std::asin(std::clamp(-o(2, 0), -1.0, 1.0)), std::atan2(o(2, 1), o(2, 2))};
}

Matrix3d from_euler_zyx(const Vector3d& e) {
  return (Eigen::AngleAxisd(e[0], Vector3d::UnitZ()) * Eigen::AngleAxisd(e[1], Vector3d::UnitY()) *
          Eigen::AngleAxisd(e[2], Vector3d::UnitX()))
      .toRotationMatrix();
}

double lerp(double a, double b, double t) { return (1.0 - t) * a + t * b; }

// a + t (b - a) with b - a taken the shorter way round the circle.
double lerp_angle(double a, double b, double t) {
  double d = std::remainder(b - a, 2.0 * std::numbers::pi);
  return a + t * d;
}

CameraIntrinsics lerp_lens(const CameraIntrinsics& a, const CameraIntrinsics& b, double t) {
  CameraIntrinsics l;
  l.fov_y = lerp(a.fov_y, b.fov_y, t);
  l.aspect = lerp(a.aspect, b.aspect, t);
  l.skew = lerp(a.skew, b.skew, t);
  l.cop_u = lerp(a.cop_u, b.cop_u, t);
  l.cop_v = lerp(a.cop_v, b.cop_v, t);
  l.near = lerp(a.near, b.near, t);
  l.far = lerp(a.far, b.far, t);
  return l;
}

}  // namespace

Matrix3d look_at_rotation(const Vector3d& from, const Vector3d& at, const Vector3d& up) {
  const Vector3d back = from - at;
  if (!(back.norm() > 0.0)) throw std::invalid_argument("from and at are the same point");
  const Vector3d w = back.normalized();
  const Vector3d right = up.cross(w);
  if (!(right.norm() > 1e-9 * up.norm()) || !(up.norm() > 0.0))
    throw std::invalid_argument("up is zero or parallel to the viewing direction");
  const Vector3d u = right.normalized();
  const Vector3d v = w.cross(u);
  Matrix3d r;
  r.row(0) = u;
  r.row(1) = v;
  r.row(2) = w;
  return r;
}

Mat4 perspective_matrix(const CameraIntrinsics& l) { return perspective_a(l.near / l.far) * perspective_b(l); }

Mat4 perspective_a(double k) {
  Mat4 p = Mat4::Identity();
  p(2, 2) = -1.0 / (1.0 + k);
  p(2, 3) = k / (1.0 + k);
  p(3, 2) = -1.0;
  p(3, 3) = 0.0;
  return p;
}

Mat4 perspective_b(const CameraIntrinsics& l) {
  Mat4 p = Mat4::Identity();
  p(0, 0) = l.aspect;
  p(0, 1) = l.skew;
  p(0, 2) = l.cop_u;
  p(1, 2) = l.cop_v;
  return p;
}

Mat4 view_scale(const CameraIntrinsics& l) {
  const double c = 1.0 / std::tan(l.fov_y / 2.0);
  Mat4 s = Mat4::Identity();
  s(0, 0) = c / l.far;
  s(1, 1) = c / l.far;
  s(2, 2) = 1.0 / l.far;
  return s;
}

Mat4 view_rotation(const Matrix3d& r) {
  Mat4 m = Mat4::Identity();
  m.topLeftCorner<3, 3>() = r;
  return m;
}

Mat4 view_translation(const Vector3d& from) {
  Mat4 m = Mat4::Identity();
  m.topRightCorner<3, 1>() = -from;
  return m;
}

Mat4 view_part(const CameraIntrinsics& l, const Matrix3d& r, const Vector3d& from) {
  return view_scale(l) * view_rotation(r) * view_translation(from);
}

Mat4 camera_matrix(const CameraParams& c) {
  return perspective_matrix(c.lens) * view_part(c.lens, look_at_rotation(c.from, c.at, c.up), c.from);
}

CameraKey camera_key(const CameraParams& c) {
  const Mat4 srt = view_part(c.lens, look_at_rotation(c.from, c.at, c.up), c.from);
  return CameraKey{perspective_b(c.lens) * srt, srt, c.lens.near / c.lens.far};
}

CameraKey camera_key(const Mat4& m, double k) { return CameraKey{m, m, k}; }

Result<std::vector<Mat4>> interpolate_cameras(InterpolationMethod method, std::span<const double> key_times,
                                              std::span<const CameraKey> keys, std::span<const double> frame_times,
                                              const CombinationOptions& o) {
  std::vector<Mat4> matrices, origins;
  std::vector<double> ks;
  for (const CameraKey& k : keys) {
    matrices.push_back(k.matrix);
    origins.push_back(k.origin);
    ks.push_back(k.k);
  }
  Result<std::vector<Mat4>> m = interpolate_keyframes(method, key_times, matrices, origins, frame_times, o);
  if (!m) return m;
  // k(t) piecewise linear: the linear method's weights do exactly that.
  const auto lin = frame_weights(InterpolationMethod::Linear, key_times, frame_times);
  std::vector<Mat4>& out = m.value();
  for (std::size_t f = 0; f < out.size(); ++f) {
    double k = 0.0;
    for (const WeightTerm& t : lin[f].terms) k += t.weight * ks[t.key];
    out[f] = perspective_a(k) * out[f];
  }
  return m;
}

namespace {
// The interpolated parameters: lens, rotation and position.
struct LerpedCamera {
  CameraIntrinsics lens;
  Matrix3d rotation;
  Vector3d from;
};
LerpedCamera lerp_camera(const CameraParams& a, const CameraParams& b, double t) {
  const Vector3d ea = euler_zyx(look_at_rotation(a.from, a.at, a.up).transpose());
  const Vector3d eb = euler_zyx(look_at_rotation(b.from, b.at, b.up).transpose());
  const Vector3d e(lerp_angle(ea[0], eb[0], t), lerp(ea[1], eb[1], t), lerp_angle(ea[2], eb[2], t));
  return {lerp_lens(a.lens, b.lens, t), from_euler_zyx(e).transpose(), (1.0 - t) * a.from + t * b.from};
}
}  // namespace

Mat4 camera_parameter_lerp_matrix(const CameraParams& a, const CameraParams& b, double t) {
  const LerpedCamera c = lerp_camera(a, b, t);
  return perspective_matrix(c.lens) * view_part(c.lens, c.rotation, c.from);
}

Mat4 camera_parameter_lerp_affine(const CameraParams& a, const CameraParams& b, double t) {
  const LerpedCamera c = lerp_camera(a, b, t);
  return perspective_b(c.lens) * view_part(c.lens, c.rotation, c.from);
}

}  // namespace posefair
