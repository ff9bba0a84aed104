#pragma once
// The reproduction example of docs/quaternion-splines.md, built like the paper's Section 4
// case (its keyframe values are not printed): 7 keyframes one second apart whose z component
// is always zero (so the path stays on a 2-sphere of S³), with zero angular velocity at both ends.
#include <cstdint>
#include <numbers>
#include <random>

#include "posefair/core/quaternion_spline.hpp"

namespace posefair {

inline SplineKeyframes seven_keyframe_example() {
  SplineKeyframes k;
  k.time = {0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0};
  // (w, x, y, 0), normalised by initial_spline; neighbours are 40°–75° apart on S³.
  k.orientation = {Quat(1.0, 0.0, 0.0, 0.0),  Quat(0.7, 0.7, 0.1, 0.0),  Quat(0.1, 0.9, 0.4, 0.0),
                   Quat(-0.3, 0.5, 0.8, 0.0), Quat(0.2, 0.0, 1.0, 0.0),  Quat(0.7, -0.3, 0.6, 0.0),
                   Quat(0.9, -0.4, -0.1, 0.0)};
  for (Quat& q : k.orientation) q.normalize();
  k.omega_start = Vec3::Zero();
  k.omega_end = Vec3::Zero();
  return k;
}

// Key sets of the same kind for checking claims beyond one example: 7 keyframes one second
// apart, z component zero, zero end velocities; each key is the previous one moved along a
// great circle of the (w, x, y) sphere in a random direction by an angle uniform in
// [min_step, max_step] degrees on S³ (twice that of rotation; the example's steps are 41°–45°).
// Deterministic for a seed.
inline SplineKeyframes random_seven_keyframes(std::uint64_t seed, double min_step = 30.0, double max_step = 50.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  SplineKeyframes k;
  Eigen::Vector3d q(1.0, 0.0, 0.0);  // (w, x, y)
  for (int i = 0; i < 7; ++i) {
    k.time.push_back(static_cast<double>(i));
    k.orientation.push_back(Quat(q.x(), q.y(), q.z(), 0.0));
    // A random unit tangent at q, then the great circle through it.
    const double phi = 2.0 * std::numbers::pi * u01(rng);
    const Eigen::Vector3d a = q.unitOrthogonal(), b = q.cross(a);
    const Eigen::Vector3d tangent = std::cos(phi) * a + std::sin(phi) * b;
    const double step = (min_step + (max_step - min_step) * u01(rng)) * std::numbers::pi / 180.0;
    q = (std::cos(step) * q + std::sin(step) * tangent).normalized();
  }
  k.omega_start = Vec3::Zero();
  k.omega_end = Vec3::Zero();
  return k;
}

}  // namespace posefair
