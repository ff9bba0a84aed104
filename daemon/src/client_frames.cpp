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
  // R = Ry(y) Rx(x) Rz(z), so R12 = -sin x, (R02, R22) = cos x (sin y, cos y) and
  // (R10, R11) = cos x (sin z, cos z); x within ±90°, as Unity's own eulerAngles (up to a turn).
  // At x = ±90° only y ± z is defined: z = 0 takes it all into y. Closed form, a few trig calls:
  // this runs per pose on the publisher thread.
  const Quat q = unity_q.normalized();
  const double w = q.w(), x = q.x(), y = q.y(), z = q.z();
  const double r12 = 2.0 * (y * z - w * x);
  const double ax = std::asin(std::clamp(-r12, -1.0, 1.0));
  double ay = 0.0, az = 0.0;
  if (std::abs(r12) < 1.0 - 1e-12) {
    ay = std::atan2(2.0 * (x * z + w * y), 1.0 - 2.0 * (x * x + y * y));
    az = std::atan2(2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z));
  } else {
    ay = std::atan2(-2.0 * (x * z - w * y), 1.0 - 2.0 * (y * y + z * z));
  }
  return {fold_degrees(ax * kToDegrees), fold_degrees(ay * kToDegrees), fold_degrees(az * kToDegrees)};
}

HeadAngles head_angles(const Quat& q_in) {
  // R = Rz(yaw) Ry(b) Rx(roll) with b = -pitch (posefair's +y rotation is nose down, a head's
  // pitch is up): R20 = -sin b, (R10, R00) = cos b (sin yaw, cos yaw), (R21, R22) = cos b
  // (sin roll, cos roll). At b = ±90° roll = 0 takes yaw ± roll into yaw.
  const Quat q = q_in.normalized();
  const double w = q.w(), x = q.x(), y = q.y(), z = q.z();
  const double r20 = 2.0 * (x * z - w * y);
  const double b = std::asin(std::clamp(-r20, -1.0, 1.0));
  double yaw = 0.0, roll = 0.0;
  if (std::abs(r20) < 1.0 - 1e-12) {
    yaw = std::atan2(2.0 * (x * y + w * z), 1.0 - 2.0 * (y * y + z * z));
    roll = std::atan2(2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y));
  } else {
    yaw = std::atan2(-2.0 * (x * y - w * z), 1.0 - 2.0 * (x * x + z * z));
  }
  return HeadAngles{fold_degrees(yaw * kToDegrees), fold_degrees(-b * kToDegrees), fold_degrees(roll * kToDegrees)};
}

Vec3 opentrack_position_cm(const Vec3& p) { return 100.0 * Vec3(-p.y(), p.z(), -p.x()); }

}  // namespace posefair::daemon
