// Euler angles <-> quaternions for BVH channels, with the inverse choosing the solution
// nearest to a reference so rewritten files stay close to the originals.
#include "posefair/core/euler_angles.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace posefair {

namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
constexpr double kRadToDeg = 180.0 / std::numbers::pi;

Vec3 unit_axis(Axis a) { return Vec3::Unit(static_cast<Eigen::Index>(a)); }

Eigen::Matrix3d elementary(int axis, double radians) {
  return Eigen::AngleAxisd(radians, Vec3::Unit(axis)).toRotationMatrix();
}

// The angle of R_axis(θ) ≈ m, from the two entries that hold cos θ and sin θ.
double elementary_angle(const Eigen::Matrix3d& m, int axis) {
  const int a = (axis + 1) % 3;
  const int b = (axis + 2) % 3;
  return std::atan2(m(b, a), m(a, a));
}

double unwrap_toward(double degrees, double reference) {
  return degrees + 360.0 * std::round((reference - degrees) / 360.0);
}

}  // namespace

std::optional<Axis> axis_from_char(char c) {
  switch (c) {
    case 'X': case 'x': return Axis::X;
    case 'Y': case 'y': return Axis::Y;
    case 'Z': case 'z': return Axis::Z;
    default: return std::nullopt;
  }
}

Quat euler_to_quat(std::span<const Axis> axes, std::span<const double> degrees) {
  if (axes.size() != degrees.size())
    throw std::invalid_argument("euler_to_quat: axes and angles differ in number");
  Quat q = Quat::Identity();
  for (std::size_t i = 0; i < axes.size(); ++i)
    q = q * Quat(Eigen::AngleAxisd(degrees[i] * kDegToRad, unit_axis(axes[i])));
  return q;
}

std::array<double, 3> quat_to_euler_nearest(const Quat& q_in, const std::array<Axis, 3>& axes,
                                            const std::array<double, 3>& reference_in) {
  std::array<double, 3> reference = reference_in;  // a non-finite reference counts as 0
  for (double& r : reference)
    if (!std::isfinite(r)) r = 0.0;
  const int i = static_cast<int>(axes[0]);
  const int j = static_cast<int>(axes[1]);
  const int k = static_cast<int>(axes[2]);
  if (i == j || j == k || i == k)
    throw std::invalid_argument("quat_to_euler_nearest: the three axes must be distinct");
  const Quat q = q_in.normalized();
  const Eigen::Matrix3d r = q.toRotationMatrix();
  // R = R_i(a) R_j(b) R_k(c): with s = +1 for the cyclic orders (xyz, yzx, zxy), -1 otherwise,
  //   R(i,k) = s sin b,  R(j,k) = -s sin a cos b,  R(k,k) = cos a cos b,
  //   R(i,j) = -s cos b sin c,  R(i,i) = cos b cos c.
  // The second solution is (a + 180°, 180° - b, c + 180°).
  const double s = (j == (i + 1) % 3) ? 1.0 : -1.0;
  const double cb = std::hypot(r(i, i), r(i, j));
  const double a1 = std::atan2(-s * r(j, k), r(k, k));
  const double b_first = std::atan2(s * r(i, k), cb);
  const double b_second = std::atan2(s * r(i, k), -cb);

  struct Candidate {
    std::array<double, 3> deg;
    double error = 0.0;
  };
  std::vector<Candidate> candidates;
  const auto add = [&](double a_deg, double b_deg, double c_deg) {
    Candidate c;
    c.deg = {unwrap_toward(a_deg, reference[0]), unwrap_toward(b_deg, reference[1]),
             unwrap_toward(c_deg, reference[2])};
    const Quat back = euler_to_quat(axes, c.deg);
    c.error = (back.conjugate() * q).vec().norm();  // sin of half the rotation between them
    candidates.push_back(c);
  };
  for (const double b : {b_first, b_second}) {
    const double a = (b == b_first) ? a1 : a1 + std::numbers::pi;
    // The last angle is solved exactly from the other two (R_k(c) = R_j(b)ᵀ R_i(a)ᵀ R), which
    // stays exact near gimbal lock where a from atan2 of two tiny entries is only approximate.
    // At (or near) lock only a combination of the first and last angles is defined, so also
    // try keeping either of them at its reference and solving the other.
    const Eigen::Matrix3d rb = elementary(j, b);
    const auto solve_last = [&](double a_rad) {
      return elementary_angle(rb.transpose() * elementary(i, a_rad).transpose() * r, k);
    };
    const double a_ref = reference[0] * kDegToRad;
    const double c_ref = reference[2] * kDegToRad;
    const double a_solved = elementary_angle(r * elementary(k, c_ref).transpose() * rb.transpose(), i);
    add(a * kRadToDeg, b * kRadToDeg, solve_last(a) * kRadToDeg);
    add(reference[0], b * kRadToDeg, solve_last(a_ref) * kRadToDeg);
    add(a_solved * kRadToDeg, b * kRadToDeg, reference[2]);
  }

  double min_error = std::numeric_limits<double>::infinity();
  for (const Candidate& c : candidates) min_error = std::min(min_error, c.error);
  const double accept = std::max(1e-13, 2.0 * min_error);
  const Candidate* best = nullptr;
  double best_distance = std::numeric_limits<double>::infinity();
  for (const Candidate& c : candidates) {
    if (c.error > accept) continue;
    double d = 0.0;
    for (int n = 0; n < 3; ++n) d += (c.deg[n] - reference[n]) * (c.deg[n] - reference[n]);
    if (d < best_distance) {
      best_distance = d;
      best = &c;
    }
  }
  return best != nullptr ? best->deg : candidates.front().deg;  // null only for a non-finite q
}

}  // namespace posefair
