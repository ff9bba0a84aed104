#pragma once
// Synthetic raw IMU recordings with a known true orientation, for the estimator tests: the
// sensor turns with a smooth angular velocity (or rests), the gyroscope reads that velocity
// plus a constant bias and seeded noise, the accelerometer reads gravity (specific force, up)
// and the magnetometer an earth field pointing north and down, both in the sensor frame.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "posefair/core/sample.hpp"
#include "posefair/core/so3.hpp"

namespace posefair::test {

inline const Vec3 kGravityUp(0.0, 0.0, 9.81);
inline const Vec3 kEarthField(0.0, 20.0, -40.0);  // µT: north and down (ENU)

struct ImuRecordingSpec {
  double rate_hz = 200.0;
  double seconds = 20.0;
  double rest_seconds = 0.0;       // at rest first, then moving
  Vec3 gyro_bias = Vec3::Zero();   // rad/s
  double gyro_noise = 0.0;         // rad/s, standard deviation
  double accel_noise = 0.0;        // m/s^2
  double mag_noise = 0.0;          // µT
  Quat start = Quat::Identity();
  unsigned seed = 1;
};

struct SyntheticImu {
  std::vector<Sample> samples;
  std::vector<Quat> truth;  // sensor to ENU
  double dt = 0.0;
};

inline Vec3 synthetic_rate(double t) {
  return Vec3(1.0 * std::sin(0.7 * t), 0.8 * std::cos(0.5 * t), 1.2 * std::sin(0.3 * t + 0.4));
}

inline SyntheticImu make_synthetic_imu(const ImuRecordingSpec& spec) {
  SyntheticImu out;
  out.dt = 1.0 / spec.rate_hz;
  std::mt19937 rng(spec.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const auto noise = [&](double sigma) {
    const double x = normal(rng), y = normal(rng), z = normal(rng);
    return Vec3(x * sigma, y * sigma, z * sigma);
  };
  Quat q = spec.start.normalized();
  const int n = static_cast<int>(std::lround(spec.seconds * spec.rate_hz));
  const auto rate = [&](double t) {
    return t < spec.rest_seconds ? Vec3::Zero() : synthetic_rate(t - spec.rest_seconds);
  };
  for (int k = 0; k < n; ++k) {
    const double t = k * out.dt;
    // The gyroscope at sample k reads the rate held over the step that ends at k, as the
    // estimators integrate it (from sample k-1 to k).
    const Vec3 w = rate(std::max(0.0, t - out.dt));
    if (k > 0) q = (q * so3::from_rotation_vector(w * out.dt)).normalized();
    Sample s;
    s.sequence = static_cast<std::uint64_t>(k);
    s.time = t;
    s.gyro = w + spec.gyro_bias + noise(spec.gyro_noise);
    s.accel = q.conjugate() * kGravityUp + noise(spec.accel_noise);
    s.mag = q.conjugate() * kEarthField + noise(spec.mag_noise);
    s.flags = kHasGyro | kHasAccel | kHasMag | kNoOrientation;
    out.samples.push_back(s);
    out.truth.push_back(q);
  }
  return out;
}

}  // namespace posefair::test
