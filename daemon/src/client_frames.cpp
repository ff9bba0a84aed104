#include "posefair/daemon/client_frames.hpp"

#include <cmath>

#include "posefair/core/euler_angles.hpp"

namespace posefair::daemon {
namespace {

// Angles at the gimbal lock or from the nearer of two solutions, folded into [-180, 180].
double fold_degrees(double a) {
  a = std::remainder(a, 360.0);
  return a == -180.0 ? 180.0 : a;
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
  // R = Ry(y) Rx(x) Rz(z): the Tait–Bryan angles about Y, X, Z in that order, the solution
  // nearest to zero (x within ±90°), as Unity's own eulerAngles picks it (up to a turn).
  static constexpr std::array<Axis, 3> kYxz = {Axis::Y, Axis::X, Axis::Z};
  const std::array<double, 3> yxz = quat_to_euler_nearest(unity_q, kYxz, {0.0, 0.0, 0.0});
  return {fold_degrees(yxz[1]), fold_degrees(yxz[0]), fold_degrees(yxz[2])};
}

HeadAngles head_angles(const Quat& q) {
  // R = Rz(yaw) Ry(-pitch) Rx(roll): posefair's +y rotation is nose down, a head's pitch is up.
  static constexpr std::array<Axis, 3> kZyx = {Axis::Z, Axis::Y, Axis::X};
  const std::array<double, 3> zyx = quat_to_euler_nearest(q, kZyx, {0.0, 0.0, 0.0});
  return HeadAngles{fold_degrees(zyx[0]), fold_degrees(-zyx[1]), fold_degrees(zyx[2])};
}

Vec3 opentrack_position_cm(const Vec3& p) { return 100.0 * Vec3(-p.y(), p.z(), -p.x()); }

}  // namespace posefair::daemon
