#pragma once
// Sequences with known difference structure, shared by the core tests.
#include <random>
#include <vector>

#include "posefair/core/so3.hpp"

namespace posefair::testing {

// q_{i+1} = q_i exp(u_i) with u_i = a + b·i: W¹ is linear in i, so W³ = 0 (constant angular
// acceleration); with b = 0 it is constant angular velocity (W² = 0).
inline std::vector<Quat> sequence_with_linear_w1(std::size_t n, const Quat& start, const Vec3& a, const Vec3& b) {
  std::vector<Quat> q{start};
  for (std::size_t i = 0; i + 1 < n; ++i) q.push_back((q.back() * so3::exp(a + b * static_cast<double>(i))).normalized());
  return q;
}

inline Quat random_unit_quaternion(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
}

inline Vec3 random_direction(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Vec3(g(rng), g(rng), g(rng)).normalized();
}

}  // namespace posefair::testing
