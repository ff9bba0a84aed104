#pragma once
// Smooth reference motion plus bounded random perturbation, in the manner of Lee & Shin's
// Section 6: orientations perturbed by random rotations exp(δ) with ‖δ‖ < a bound (δ in the
// papers' half-angle convention, so dist(noisy, truth) < bound), positions in a cube
// perturbed by random offsets inside a ball. Deterministic for a given seed.
#include <cstdint>
#include <random>

#include "posefair/core/pose_sequence.hpp"

namespace posefair {

struct SyntheticMotionSpec {
  std::size_t samples = 100;
  double sample_rate_hz = 100.0;
  double cycles = 1.0;              // roughly how many slow oscillations the truth makes in total
  double rotation_noise = 0.1;      // ‖δ_r‖ < this (rad, dist on S³)
  bool with_position = true;
  double cube_size = 400.0;         // truth positions stay inside [0, cube_size]³ (mm)
  double position_noise = 10.0;     // ‖δ_t‖ < this (mm)
  std::uint64_t seed = 1;
};

struct SyntheticMotion {
  PoseSequence truth;   // smooth (analytic: exp of sums of sines; positions sines in the cube)
  PoseSequence noisy;   // truth ∘ perturbation
};

SyntheticMotion make_synthetic_motion(const SyntheticMotionSpec& spec);

// A random direction and a magnitude uniform in [0, bound): the perturbations of Section 6.
Vec3 random_offset(std::mt19937_64& rng, double bound);

}  // namespace posefair
