#include "posefair/core/synthetic_motion.hpp"

#include <cmath>
#include <numbers>
#include <random>

namespace posefair {

Vec3 random_offset(std::mt19937_64& rng, double bound) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  Vec3 dir(gauss(rng), gauss(rng), gauss(rng));
  while (dir.norm() < 1e-12) dir = Vec3(gauss(rng), gauss(rng), gauss(rng));
  return dir.normalized() * (bound * uni(rng));
}

SyntheticMotion make_synthetic_motion(const SyntheticMotionSpec& spec) {
  std::mt19937_64 rng(spec.seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  constexpr double two_pi = 2.0 * std::numbers::pi;

  // Two sine components per axis with random frequency, amplitude and phase; the truth is
  // exp(a(s)) with s = i/(n-1) ∈ [0, 1], smooth at every scale the noise lives on.
  struct Wave { double amp, freq, phase; };
  Wave rot[3][2], pos[3][2];
  for (auto& axis : rot)
    for (Wave& w : axis) w = {0.25 + 0.35 * uni(rng), spec.cycles * (0.5 + uni(rng)), two_pi * uni(rng)};
  for (auto& axis : pos)
    for (Wave& w : axis) w = {0.5 + 0.5 * uni(rng), spec.cycles * (0.5 + uni(rng)), two_pi * uni(rng)};

  SyntheticMotion out;
  const std::size_t n = spec.samples;
  const double half = spec.cube_size / 2.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double s = n > 1 ? static_cast<double>(i) / static_cast<double>(n - 1) : 0.0;
    Vec3 a, p;
    for (int k = 0; k < 3; ++k) {
      a[k] = 0.0;
      p[k] = 0.0;
      for (const Wave& w : rot[k]) a[k] += w.amp * std::sin(two_pi * w.freq * s + w.phase);
      for (const Wave& w : pos[k]) p[k] += 0.5 * w.amp * std::sin(two_pi * w.freq * s + w.phase);
      p[k] = half + half * 0.9 * p[k];  // |0.5·Σ amp| ≤ 1, so p stays inside the cube
    }
    const double t = static_cast<double>(i) / spec.sample_rate_hz;
    const Quat q = so3::exp(a);
    out.truth.time.push_back(t);
    out.truth.orientation.push_back(q);
    out.noisy.time.push_back(t);
    out.noisy.orientation.push_back((q * so3::exp(random_offset(rng, spec.rotation_noise))).normalized());
    if (spec.with_position) {
      out.truth.position.push_back(p);
      out.noisy.position.push_back(p + random_offset(rng, spec.position_noise));
    }
  }
  return out;
}

}  // namespace posefair
