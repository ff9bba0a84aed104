#include "posefair/daemon/client_frames.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "posefair/core/euler_angles.hpp"

namespace posefair::daemon {
namespace {

constexpr double kToDegrees = 180.0 / std::numbers::pi;

// An angle folded into [-180, 180] (-180 written as 180).
double fold_degrees(double a) {
  a = std::remainder(a, 360.0);
  return a == -180.0 ? 180.0 : a;
}

// The Tait–Bryan angles (a, b, c) in degrees of R = R_i(a) R_j(b) R_k(c) (i, j, k distinct axes,
// 0 = x), the principal solution: b within ±90°, a and c in [-180, 180]. With s = +1 for a cyclic
// order (xyz, yzx, zxy) and -1 otherwise, R(i,k) = s sin b, (-s R(j,k), R(k,k)) = cos b (sin a,
// cos a) and (-s R(i,j), R(i,i)) = cos b (sin c, cos c). At b = ±90° only a ± c is defined: c = 0
// takes it all into a. Closed form, a few trig calls: this runs per pose on the publisher thread.
std::array<double, 3> principal_tait_bryan(const Quat& q, int i, int j, int k) {
  const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
  const double s = ((j - i + 3) % 3 == 1) ? 1.0 : -1.0;
  const double sin_b = std::clamp(s * r(i, k), -1.0, 1.0);
  double a = 0.0, c = 0.0;
  if (std::abs(sin_b) < 1.0 - 1e-12) {
    a = std::atan2(-s * r(j, k), r(k, k));
    c = std::atan2(-s * r(i, j), r(i, i));
  } else {
    a = std::atan2(s * r(k, j), r(j, j));
  }
  return {fold_degrees(a * kToDegrees), std::asin(sin_b) * kToDegrees, fold_degrees(c * kToDegrees)};
}

}  // namespace

Quat rotation_from_zyx_degrees(double yaw, double pitch, double roll) {
  static constexpr Axis kZyx[] = {Axis::Z, Axis::Y, Axis::X};
  const double degrees[] = {yaw, pitch, roll};
  return euler_to_quat(kZyx, degrees);
}

// Unity's axes in posefair's: right = -y, up = z, forward = x. A change of axes with a
// reflection (det -1): the rotation's axis maps like a vector, its sense flips, so the vector
// part of the quaternion is mapped and negated.
Vec3 unity_position(const Vec3& p) { return Vec3(-p.y(), p.z(), p.x()); }

Quat unity_rotation(const Quat& q) {
  const Vec3 axis = -unity_position(q.vec());
  return Quat(q.w(), axis.x(), axis.y(), axis.z());
}

std::array<double, 3> unity_euler_zxy(const Quat& unity_q) {
  // R = Ry(y) Rx(x) Rz(z): x within ±90°, as Unity's own eulerAngles (up to a turn).
  const std::array<double, 3> yxz = principal_tait_bryan(unity_q, 1, 0, 2);
  return {yxz[1], yxz[0], yxz[2]};
}

HeadAngles head_angles(const Quat& q) {
  // R = Rz(yaw) Ry(b) Rx(roll) with b = -pitch: posefair's +y rotation is nose down, a head's
  // pitch is up.
  const std::array<double, 3> zyx = principal_tait_bryan(q, 2, 1, 0);
  return HeadAngles{zyx[0], fold_degrees(-zyx[1]), zyx[2]};
}

Vec3 opentrack_position_cm(const Vec3& p) { return 100.0 * Vec3(-p.y(), p.z(), -p.x()); }

}  // namespace posefair::daemon
