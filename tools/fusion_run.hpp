#pragma once
// Running an orientation estimator over a raw IMU recording (posefair fuse, posefair bench
// fusion): one update per sample, dt from consecutive sample times, the estimate after each.
#include <string>
#include <vector>

#include "posefair/core/orientation_estimator.hpp"
#include "posefair/formats/imu_csv.hpp"

namespace posefair::tools {

// The estimate after each sample (identity before the first accelerometer reading).
std::vector<Quat> run_estimator(OrientationEstimator& estimator, const formats::ImuRecording& recording);

// One line of the estimator's counters, e.g. for stderr after a run.
std::string describe_estimator_state(const EstimatorState& state);

}  // namespace posefair::tools
