#include "fusion_run.hpp"

#include <cmath>
#include <cstdio>

namespace posefair::tools {

std::vector<Quat> run_estimator(OrientationEstimator& estimator, const formats::ImuRecording& recording) {
  std::vector<Quat> out;
  out.reserve(recording.samples.size());
  double previous = recording.samples.empty() ? 0.0 : recording.samples.front().time;
  for (const Sample& s : recording.samples) {
    estimator.update(s, s.time - previous);
    previous = s.time;
    out.push_back(estimator.orientation());
  }
  return out;
}

std::string describe_estimator_state(const EstimatorState& s) {
  constexpr double kDeg = 180.0 / M_PI;
  char line[512];
  std::snprintf(line, sizeof line,
                "%llu updates; gyro bias (%.3f, %.3f, %.3f) deg/s ± %.3f; %s; %s; left out: %llu non-finite, "
                "%llu stuck magnetometer, %llu without magnetometer; %llu saturated gyroscope; %llu bad time steps; "
                "%llu gaps; %llu state resets",
                static_cast<unsigned long long>(s.updates), s.gyro_bias.x() * kDeg, s.gyro_bias.y() * kDeg,
                s.gyro_bias.z() * kDeg, s.bias_sigma * kDeg, s.at_rest ? "at rest" : "moving",
                s.mag_disturbed ? "magnetic disturbance" : "field undisturbed",
                static_cast<unsigned long long>(s.nonfinite), static_cast<unsigned long long>(s.mag_stuck),
                static_cast<unsigned long long>(s.mag_absent), static_cast<unsigned long long>(s.gyro_saturated),
                static_cast<unsigned long long>(s.bad_time_steps), static_cast<unsigned long long>(s.gaps),
                static_cast<unsigned long long>(s.state_resets));
  return line;
}

}  // namespace posefair::tools
