#include "posefair/core/so3.hpp"

#include <cmath>

namespace posefair::so3 {

Quat exp(const Vec3& v) {
  const double theta = v.norm();
  // sin(θ)/θ; below 1e-4 the series to θ⁴ is exact in double precision.
  const double t2 = theta * theta;
  const double sinc = theta < 1e-4 ? 1.0 - t2 / 6.0 + t2 * t2 / 120.0 : std::sin(theta) / theta;
  return Quat(std::cos(theta), sinc * v.x(), sinc * v.y(), sinc * v.z());
}

Vec3 log(const Quat& q_in) {
  // Choose the hemisphere w >= 0 so the result is the shorter rotation.
  const Quat q = q_in.w() < 0.0 ? Quat(-q_in.coeffs()) : q_in;
  const Vec3 v = q.vec();
  const double s = v.norm();
  const double w = q.w();
  // θ = atan2(s, w) is well conditioned everywhere, including near θ = pi/2 (w -> 0).
  // For small s use atan(x)/x = 1 − x²/3 + x⁴/5 − x⁶/7 + x⁸/9 with x = s/w (w ≈ |q| there): it
  // avoids 0/0, and under x = 0.01 the first term left out (x¹⁰/11) is below a double's rounding,
  // so it is exact where most samples' steps lie, at a fraction of atan2's cost.
  double scale;
  if (s < 1e-2 * w) {
    const double x = s / w;
    const double x2 = x * x;
    scale = (1.0 + x2 * (-1.0 / 3.0 + x2 * (1.0 / 5.0 + x2 * (-1.0 / 7.0 + x2 / 9.0)))) / w;
  } else {
    scale = std::atan2(s, w) / s;
  }
  return scale * v;
}

Quat slerp(double t, const Quat& a, const Quat& b) {
  return a * exp(t * log(a.conjugate() * b));
}

double dist(const Quat& a, const Quat& b) {
  // Angle between unit vectors via 2·atan2(|a-b|, |a+b|): accurate at 0 where acos is not.
  const Eigen::Vector4d ca = a.coeffs();
  const Eigen::Vector4d cb = a.dot(b) < 0.0 ? Eigen::Vector4d(-b.coeffs()) : Eigen::Vector4d(b.coeffs());
  return 2.0 * std::atan2((ca - cb).norm(), (ca + cb).norm());
}

void make_continuous(std::span<Quat> q) {
  if (q.empty()) return;
  if (q[0].w() < 0.0) q[0].coeffs() = -q[0].coeffs();
  for (std::size_t i = 1; i < q.size(); ++i) q[i] = aligned_to(q[i], q[i - 1]);
}

}  // namespace posefair::so3
