#pragma once
// A tracker stream with a gyroscope, for the gyro-aided fairing tests (engine and daemon): a
// lively motion integrated finely from a known body rate, measured with white jitter, each
// sample also carrying a gyro reading with an optional bias, time offset and mounting.
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "posefair/core/sample.hpp"
#include "posefair/core/so3.hpp"

namespace posefair::testing {

// Body angular velocity (rad/s): several hundred °/s at times.
inline Vec3 tracker_body_rate(double t) {
  return {4.0 * std::sin(2.0 * M_PI * 0.7 * t), 3.0 * std::cos(2.0 * M_PI * 0.45 * t + 0.3),
          2.5 * std::sin(2.0 * M_PI * 1.3 * t + 1.0)};
}

struct GyroTrackerSpec {
  double rate_hz = 200.0;
  double seconds = 10.0;
  double start_time = 0.0;
  double jitter_deg = 1.0;           // RMS rotation angle of the white jitter
  Vec3 bias = Vec3::Zero();          // rad/s, gyro frame
  double offset = 0.0;               // the gyro reading stamped t + offset measured the motion at t
  Quat mounting = Quat::Identity();  // gyro frame to body frame
  std::uint64_t seed = 1;
};

struct GyroTrackerStream {
  std::vector<Quat> truth;
  std::vector<Sample> samples;  // orientation and kHasGyro
};

inline GyroTrackerStream make_gyro_tracker_stream(const GyroTrackerSpec& spec) {
  std::mt19937_64 rng(spec.seed);
  std::normal_distribution<double> n(0.0, spec.jitter_deg * M_PI / 180.0 / std::sqrt(3.0));
  GyroTrackerStream g;
  Quat q = Quat::Identity();
  const int substeps = 20;
  const auto count = static_cast<std::size_t>(std::lround(spec.seconds * spec.rate_hz));
  for (std::size_t i = 0; i < count; ++i) {
    const double t = static_cast<double>(i) / spec.rate_hz;
    g.truth.push_back(q);
    Sample s;
    s.stream_id = 1;
    s.sequence = i;
    s.time = spec.start_time + t;
    s.orientation = (q * so3::from_rotation_vector(Vec3(n(rng), n(rng), n(rng)))).normalized();
    s.gyro = spec.mounting.conjugate() * tracker_body_rate(t - spec.offset) + spec.bias;
    s.flags = kHasGyro;
    g.samples.push_back(s);
    for (int k = 0; k < substeps; ++k) {
      const double h = 1.0 / (spec.rate_hz * substeps);
      q = (q * so3::from_rotation_vector(tracker_body_rate(t + (k + 0.5) * h) * h)).normalized();
    }
  }
  return g;
}

// The motion of a make_gyro_tracker_stream with start_time 0, seen by a separate IMU on the
// body (a gyro_stream source): raw-only samples (kNoOrientation) at spec.rate_hz whose readings
// begin at spec.start_time, each carrying only the gyro reading (spec's mounting, bias and
// offset) plus white noise of gyro_noise rad/s per axis.
inline std::vector<Sample> make_imu_readings(const GyroTrackerSpec& spec, double gyro_noise = 0.0) {
  std::mt19937_64 rng(spec.seed + 1000);
  std::normal_distribution<double> n(0.0, gyro_noise);
  std::vector<Sample> out;
  const auto count = static_cast<std::size_t>(std::lround(spec.seconds * spec.rate_hz));
  for (std::size_t i = 0; i < count; ++i) {
    const double t = spec.start_time + static_cast<double>(i) / spec.rate_hz;
    Sample s;
    s.stream_id = 1;
    s.sequence = i;
    s.time = t;
    s.gyro = spec.mounting.conjugate() * tracker_body_rate(t - spec.offset) + spec.bias + Vec3(n(rng), n(rng), n(rng));
    s.flags = kHasGyro | kNoOrientation;
    out.push_back(s);
  }
  return out;
}

}  // namespace posefair::testing
