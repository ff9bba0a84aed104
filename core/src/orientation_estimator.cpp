// The input screening every estimator shares, and the acc/mag initial orientation.
#include "posefair/core/orientation_estimator.hpp"

#include <cmath>

namespace posefair {

namespace {
constexpr double kEstimatorDegree = M_PI / 180.0;
}

Quat orientation_from_accel_mag(const Vec3& accel, const Vec3* mag) {
  const Vec3 up = accel.normalized();
  if (mag != nullptr) {
    const Vec3 east = mag->cross(up);  // north × up = east
    if (east.norm() > 1e-6 * mag->norm()) {
      Eigen::Matrix3d earth_from_sensor;
      earth_from_sensor.row(0) = east.normalized().transpose();
      earth_from_sensor.row(2) = up.transpose();
      earth_from_sensor.row(1) = up.cross(east.normalized()).transpose();
      return Quat(earth_from_sensor).normalized();
    }
  }
  return Quat::FromTwoVectors(up, Vec3::UnitZ()).normalized();
}

void OrientationEstimator::initialise(const Vec3& accel, const Vec3* mag) {
  q_ = orientation_from_accel_mag(accel, mag);
}

void OrientationEstimator::update(const Sample& sample, double dt) {
  ++state_.updates;
  // Screen the readings: absent or non-finite ones are left out.
  const auto reading = [&](bool present, const Vec3& v) -> const Vec3* {
    if (!present) return nullptr;
    if (!v.allFinite()) {
      ++state_.nonfinite;
      return nullptr;
    }
    return &v;
  };
  ImuStep in;
  in.gyro = reading(sample.has_gyro(), sample.gyro);
  // A missing gyroscope reading is bridged with the last good one (the motion goes on; a
  // skipped step would lose its rotation for good).
  if (in.gyro != nullptr) {
    last_gyro_ = *in.gyro;
    have_gyro_ = true;
  } else if (have_gyro_ && started_) {
    in.gyro = &last_gyro_;
  }
  in.accel = reading(sample.has_accel(), sample.accel);
  if (in.accel != nullptr && in.accel->squaredNorm() == 0.0) in.accel = nullptr;
  if (limits_.use_mag) {
    in.mag = reading(sample.has_mag(), sample.mag);
    if (in.mag == nullptr && !sample.has_mag()) ++state_.mag_absent;
    if (in.mag != nullptr && in.mag->squaredNorm() == 0.0) in.mag = nullptr;
  }

  if (!started_) {
    if (in.accel == nullptr) return;  // nothing to start from yet
    if (in.mag != nullptr) last_mag_ = *in.mag;
    initialise(*in.accel, in.mag);
    started_ = true;
    state_.initialised = true;
    return;
  }
  if (!std::isfinite(dt) || dt <= 0.0) {
    ++state_.bad_time_steps;
    return;
  }
  if (dt > limits_.max_gap) {
    ++state_.gaps;
    after_gap();
    mag_unchanged_for_ = 0.0;
    have_gyro_ = false;
    return;  // the motion over the gap is unknown: continue from the next sample
  }
  in.dt = dt;

  if (in.gyro != nullptr && in.gyro->cwiseAbs().maxCoeff() >= limits_.gyro_range) {
    ++state_.gyro_saturated;
    in.gyro_saturated = true;
    after_gap();  // the integrated motion is wrong by an unknown amount: re-converge fast
  }
  if (in.mag != nullptr) {
    if (*in.mag == last_mag_) {
      mag_unchanged_for_ += dt;
      if (mag_unchanged_for_ >= limits_.mag_stuck_time) {
        ++state_.mag_stuck;
        in.mag = nullptr;
      }
    } else {
      last_mag_ = *in.mag;
      mag_unchanged_for_ = 0.0;
    }
  }

  const Quat good = q_;
  const EstimatorState kept = state_;
  step(in);
  if (!q_.coeffs().allFinite() || !state_.gyro_bias.allFinite()) {
    // Cannot happen with screened input; if it does, the last good state survives.
    q_ = good;
    state_.gyro_bias = kept.gyro_bias;
    ++state_.state_resets;
    after_gap();
  }
}

std::span<const OptionSpec, kCommonEstimatorOptionCount> common_estimator_options() {
  return detail::kCommonEstimatorOptions;
}

EstimatorLimits read_estimator_limits(const OptionReader& reader) {
  EstimatorLimits l;
  l.use_mag = reader.boolean("magnetometer");
  const double range = reader.real("gyro_range");
  if (!(range > 0.0)) throw OptionError("gyro_range", "must be positive (deg/s)");
  l.gyro_range = range * kEstimatorDegree;
  l.max_gap = reader.real("max_gap");
  if (!(l.max_gap > 0.0)) throw OptionError("max_gap", "must be positive (seconds)");
  l.mag_stuck_time = reader.real("mag_stuck_time");
  if (!(l.mag_stuck_time > 0.0)) throw OptionError("mag_stuck_time", "must be positive (seconds)");
  return l;
}

}  // namespace posefair
