#pragma once
// Mahony's explicit complementary filter (R. Mahony, T. Hamel, J.-M. Pflimlin, "Nonlinear
// complementary filters on the special orthogonal group", IEEE TAC 53(5), 2008): the gyroscope
// corrected by kp times the cross product of measured and estimated reference directions,
// plus ki times its integral (a bias estimate). A baseline for VQF (docs/fusion.md); BROAD's
// TAGP is kp = 0.74, ki = 0.0012.
#include "posefair/core/orientation_estimator.hpp"

namespace posefair {
extern const OrientationEstimatorEntry kMahonyEstimator;
}  // namespace posefair
