#pragma once
// BROAD's error measures (Laidig, Caruso, Cereatti, Seel, "BROAD - A Benchmark for Robust
// Inertial Orientation Estimation", Data 6(7):72, 2021), exactly as its evaluation defines them:
// the error quaternion in the earth frame q_err = q_est ⊗ q_ref⁻¹ (both sensor to ENU);
// total error 2·acos|w|, heading error 2·atan(|z/w|) (about the vertical), inclination error
// 2·acos(√(w² + z²)) (the tilt part); the RMSE of each over the samples that are scored
// (BROAD: movement = 1 and a valid optical reference).
#include <cstddef>
#include <cstdint>
#include <span>

#include "posefair/core/so3.hpp"

namespace posefair {

struct OrientationError {
  double total = 0.0;        // radians
  double heading = 0.0;      // radians
  double inclination = 0.0;  // radians
};

OrientationError earth_frame_error(const Quat& estimate, const Quat& reference);

struct OrientationRmse {
  double total_deg = 0.0;
  double heading_deg = 0.0;
  double inclination_deg = 0.0;
  std::size_t samples = 0;  // samples scored
};

// RMSE over the samples k with scored[k] != 0 (all three spans the same length).
// samples == 0 (and NaN errors) when none is scored.
OrientationRmse orientation_rmse(std::span<const Quat> estimate, std::span<const Quat> reference,
                                 std::span<const std::uint8_t> scored);

}  // namespace posefair
