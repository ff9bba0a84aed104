#pragma once
// Helpers shared by the rotation filter tests: angles about a fixed axis, random orientations
// and seeded noisy orientation streams.
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "posefair/core/so3.hpp"

namespace posefair::testing {

// Signed physical angle of q about `axis` (q assumed to be a rotation about that axis, w > 0 side).
inline double angle_about(const Quat& q, const Vec3& axis) {
  return 2.0 * std::atan2(q.vec().dot(axis), q.w());
}

inline Quat random_unit_quaternion(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Vector4d c(n(rng), n(rng), n(rng), n(rng));
  c.normalize();
  return Quat(c(3), c(0), c(1), c(2));
}

// The path of a noisy rotation stream: at time t the rotation vector is
// (amplitude.x sin(frequency.x t), amplitude.y cos(frequency.y t), amplitude.z sin(frequency.z t + phase)),
// each sample jittered by a rotation vector with N(0, noise) components.
struct RotationPath {
  Vec3 amplitude;
  Vec3 frequency;
  double phase = 0.0;
  double noise = 0.0;
};

// A smoothly moving, noisy orientation stream covering large angles: n samples dt apart, starting
// from a random base orientation drawn from `seed`.
inline std::vector<Quat> noisy_rotation_stream(std::uint64_t seed, int n, double dt, const RotationPath& path) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, path.noise);
  const Quat base = random_unit_quaternion(rng);
  std::vector<Quat> out;
  for (int k = 0; k < n; ++k) {
    const double t = k * dt;
    const Vec3 r(path.amplitude.x() * std::sin(path.frequency.x() * t),
                 path.amplitude.y() * std::cos(path.frequency.y() * t),
                 path.amplitude.z() * std::sin(path.frequency.z() * t + path.phase));
    const Vec3 jitter(noise(rng), noise(rng), noise(rng));
    out.push_back(base * so3::from_rotation_vector(r) * so3::from_rotation_vector(jitter));
  }
  return out;
}

}  // namespace posefair::testing
