#include "posefair/core/so3.hpp"

#include <cmath>

namespace posefair::so3 {

Quat exp(const Vec3& v) {
  // sin(θ)/θ and cos θ. Below 0.1 their series to θ⁸ and θ¹⁰ are exact in double precision (the
  // first terms left out, θ¹⁰/11! and θ¹²/12!, are under 3·10⁻¹⁸) at a fraction of sin's and cos's
  // cost, and need only θ², no square root: nearly every step and correction of a stream is that
  // small. (0/0 is avoided too.)
  const double t2 = v.squaredNorm();
  if (t2 < 0.01) {
    const double sinc = 1.0 + t2 * (-1.0 / 6.0 + t2 * (1.0 / 120.0 + t2 * (-1.0 / 5040.0 + t2 * (1.0 / 362880.0))));
    const double cosine =
        1.0 + t2 * (-1.0 / 2.0 + t2 * (1.0 / 24.0 + t2 * (-1.0 / 720.0 + t2 * (1.0 / 40320.0 + t2 * (-1.0 / 3628800.0)))));
    return Quat(cosine, sinc * v.x(), sinc * v.y(), sinc * v.z());
  }
  const double theta = std::sqrt(t2);
  const double sinc = std::sin(theta) / theta;
  return Quat(std::cos(theta), sinc * v.x(), sinc * v.y(), sinc * v.z());
}

Vec3 log(const Quat& q_in) {
  // Choose the hemisphere w >= 0 so the result is the shorter rotation.
  const Quat q = q_in.w() < 0.0 ? Quat(-q_in.coeffs()) : q_in;
  const Vec3 v = q.vec();
  const double s2 = v.squaredNorm();
  const double w = q.w();
  // θ = atan2(s, w) is well conditioned everywhere, including near θ = pi/2 (w -> 0).
  // For small s use atan(x)/x = 1 − x²/3 + x⁴/5 − … − x¹⁴/15 with x = s/w (w ≈ |q| there): it
  // avoids 0/0, and under x = 0.1 the first term left out (x¹⁶/17, 6·10⁻¹⁸) is below a double's
  // rounding, so it is exact where nearly all samples' steps and corrections lie, at a fraction
  // of atan2's cost (and from s², with one division and no square root).
  double scale;
  if (s2 < 0.01 * w * w) {
    const double inverse_w = 1.0 / w;
    const double x2 = s2 * inverse_w * inverse_w;
    scale = (1.0 + x2 * (-1.0 / 3.0 + x2 * (1.0 / 5.0 + x2 * (-1.0 / 7.0 + x2 * (1.0 / 9.0 + x2 * (-1.0 / 11.0 +
            x2 * (1.0 / 13.0 + x2 * (-1.0 / 15.0)))))))) * inverse_w;
  } else {
    const double s = std::sqrt(s2);
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
