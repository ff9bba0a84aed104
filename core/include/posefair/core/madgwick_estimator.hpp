#pragma once
// Madgwick's gradient-descent orientation filter (S. Madgwick, "An efficient orientation filter
// for inertial and inertial/magnetic sensor arrays", 2010): the gyroscope's quaternion rate
// minus beta times the normalised gradient of the accelerometer (and magnetometer) residual.
// A baseline for VQF (docs/fusion.md); BROAD's TAGP is beta = 0.12.
#include "posefair/core/orientation_estimator.hpp"

namespace posefair {
extern const OrientationEstimatorEntry kMadgwickEstimator;
}  // namespace posefair
