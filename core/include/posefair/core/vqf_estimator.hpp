#pragma once
// VQF (D. Laidig, T. Seel, "VQF: Highly accurate IMU orientation estimation with bias
// estimation and magnetic disturbance rejection", Information Fusion 91, 2023), written here
// from the paper, in 6D and 9D (docs/fusion.md):
// - strapdown integration of the bias-corrected gyroscope into q_gyr (earth-ish frame I);
// - the accelerometer rotated into I and low-pass filtered there (2nd-order Butterworth, tau_acc),
//   and the inclination correction q_acc that turns that filtered vector up;
// - rest detection (gyroscope and accelerometer near their low-passed values for rest_min_time)
//   and a Kalman filter for the gyroscope bias: measured directly at rest, and in motion from
//   the angular rate the accelerometer correction implies (per axis of the earth frame);
// - the magnetometer in the inclination-corrected frame giving a heading offset delta, updated
//   with gain from tau_mag, while the field's norm and dip agree with a reference; a field that
//   disagrees is rejected (for up to mag_max_rejection_time) and, if it stays steady while the
//   sensor moves for mag_new_time, becomes the new reference.
// Output: q = q_z(delta) ⊗ q_acc ⊗ q_gyr, sensor to ENU.
#include "posefair/core/orientation_estimator.hpp"

namespace posefair {

// The paper's parameters, its defaults (units as named; angles in degrees as the paper gives them).
struct VqfParameters {
  double tau_acc = 3.0;                    // s
  double tau_mag = 9.0;                    // s
  bool motion_bias = true;
  bool rest_bias = true;
  bool mag_rejection = true;
  double bias_sigma_init = 0.5;            // deg/s
  double bias_forgetting_time = 100.0;     // s: the uncertainty grows from 0 to 0.1 deg/s in it
  double bias_clip = 2.0;                  // deg/s
  double bias_sigma_motion = 0.1;          // deg/s
  double bias_vertical_forgetting = 1e-4;  // factor
  double bias_sigma_rest = 0.03;           // deg/s
  double rest_min_time = 1.5;              // s
  double rest_filter_tau = 0.5;            // s
  double rest_th_gyr = 2.0;                // deg/s
  double rest_th_acc = 0.5;                // m/s^2
  double mag_current_tau = 0.05;           // s
  double mag_ref_tau = 20.0;               // s
  double mag_norm_th = 0.1;                // relative
  double mag_dip_th = 10.0;                // deg
  double mag_new_time = 20.0;              // s
  double mag_new_first_time = 5.0;         // s
  double mag_new_min_gyr = 20.0;           // deg/s
  double mag_min_undisturbed_time = 0.5;   // s
  double mag_max_rejection_time = 60.0;    // s
  double mag_rejection_factor = 2.0;
};

extern const OrientationEstimatorEntry kVqfEstimator;

// The same, built directly (tests and benchmarks that vary one parameter).
std::unique_ptr<OrientationEstimator> make_vqf_estimator(const VqfParameters& parameters,
                                                         const EstimatorLimits& limits);

}  // namespace posefair
