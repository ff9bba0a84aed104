#include "posefair/core/fairing_operators.hpp"

#include <cassert>
#include <stdexcept>
#include <string>

namespace posefair {

int min_samples_for_order(int m) {
  if (m == 2) return 3;
  if (m == 3) return 4;
  throw std::invalid_argument("fairing operators exist for order 2 and 3, not " + std::to_string(m));
}

void position_targets(int m, std::span<const Vec3> p, std::span<Vec3> t) {
  const std::size_t n = p.size();
  assert(t.size() == n && n >= static_cast<std::size_t>(min_samples_for_order(m)));
  if (m == 2) {
    // D² p = 0 solved for each sample (eq. 16).
    t[0] = 2.0 * p[1] - p[2];
    for (std::size_t i = 1; i + 1 < n; ++i) t[i] = 0.5 * (p[i - 1] + p[i + 1]);
    t[n - 1] = 2.0 * p[n - 2] - p[n - 3];
    return;
  }
  // D³ p = 0 solved for each sample (eq. 18): one-sided stencils, as in the paper.
  t[0] = p[3] - 3.0 * p[2] + 3.0 * p[1];
  for (std::size_t i = 1; i + 2 < n; ++i) t[i] = p[i + 1] + (p[i - 1] - p[i + 2]) / 3.0;
  t[n - 2] = p[n - 3] + (p[n - 1] - p[n - 4]) / 3.0;
  t[n - 1] = p[n - 4] - 3.0 * p[n - 3] + 3.0 * p[n - 2];
}

void rotation_targets(int m, OperatorVariant variant, std::span<const Quat> q, std::span<Vec3> u,
                      std::span<Quat> t) {
  const std::size_t n = q.size();
  assert(t.size() == n && u.size() + 1 == n && n >= static_cast<std::size_t>(min_samples_for_order(m)));
  for (std::size_t j = 0; j + 1 < n; ++j) u[j] = so3::log(q[j].conjugate() * q[j + 1]);
  const bool printed = variant == OperatorVariant::Printed;

  if (m == 2) {
    // Ends: W² = 0 solved exactly, q_0* = q_1 q_2⁻¹ q_1 = q_1 exp(-u_1) and its mirror.
    t[0] = q[1] * so3::exp(-u[1]);
    for (std::size_t i = 1; i + 1 < n; ++i) {
      t[i] = printed ? Quat(q[i + 1] * q[i].conjugate() * q[i - 1])  // eq. 16 as printed
                     : so3::slerp(0.5, q[i - 1], q[i + 1]);          // geodesic midpoint
    }
    t[n - 1] = q[n - 2] * so3::exp(u[n - 3]);
    return;
  }

  // m = 3. Ends: u_0 = 2u_1 - u_2 and u_{n-2} = 2u_{n-3} - u_{n-4}, solved exactly.
  t[0] = q[1] * so3::exp(u[2] - 2.0 * u[1]);
  // Interior (0 < i < n-2): u_i = ½(u_{i+1} + u_{i-1}) with u_{i-1} taken from the old q_i.
  for (std::size_t i = 1; i + 2 < n; ++i) {
    const Quat printed_target = q[i + 1] * so3::exp(-0.5 * (u[i + 1] + u[i - 1]));
    t[i] = printed ? printed_target : so3::slerp(2.0 / 3.0, q[i], printed_target);
  }
  // i = n-2: u_{n-3} = ½(u_{n-2} + u_{n-4}) with u_{n-2} taken from the old q_{n-2}.
  {
    const Quat printed_target = q[n - 3] * so3::exp(0.5 * (u[n - 2] + u[n - 4]));
    t[n - 2] = printed ? printed_target : so3::slerp(2.0 / 3.0, q[n - 2], printed_target);
  }
  t[n - 1] = q[n - 2] * so3::exp(2.0 * u[n - 3] - u[n - 4]);
}

void damped_position_sweep(int m, double lambda, std::span<Vec3> p, std::span<Vec3> t) {
  position_targets(m, p, t);
  for (std::size_t i = 0; i < p.size(); ++i) p[i] = lambda * t[i] + (1.0 - lambda) * p[i];
}

void damped_rotation_sweep(int m, OperatorVariant variant, double lambda, std::span<Quat> q,
                           std::span<Vec3> u, std::span<Quat> t) {
  rotation_targets(m, variant, q, u, t);
  for (std::size_t i = 0; i < q.size(); ++i) {
    // so3::slerp takes the shorter arc (ERRATA item 6); keep q_i's hemisphere.
    q[i] = so3::slerp(lambda, q[i], t[i]).normalized();
  }
}

}  // namespace posefair
