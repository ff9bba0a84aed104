#pragma once
// Orientation from raw inertial readings (issue 17, docs/fusion.md): an estimator takes one raw
// Sample (gyroscope, accelerometer, optional magnetometer) and the time since the previous one,
// and keeps the sensor's orientation, sensor frame to an East-North-Up earth frame
// (v_earth = q v_sensor q*), the frame of BROAD's reference.
//
// Every estimator shares the screening of its input (update()), so bad readings are handled
// once and counted the same way: a NaN/inf reading is left out; a gyroscope at its range is
// integrated as read but keeps bias estimation from learning from it; a magnetometer that
// repeats the same vector for mag_stuck_time is left out as stuck; a sample with dt <= 0 or
// not finite is ignored; a step longer than max_gap is not integrated (the motion over it is
// unknown) and the estimator re-converges from the next readings. A state that would turn
// non-finite is discarded and the last good one kept. Nothing here allocates after
// construction.
//
// Registered estimators (estimator_registry.cpp) are built by name with OptionMap options, in
// the manner of the decoders and output encodings: name, description, OptionSpecs, factory.
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "posefair/core/options.hpp"
#include "posefair/core/sample.hpp"
#include "posefair/core/so3.hpp"

namespace posefair {

// What an estimator reports beside the orientation: its bias/rest/disturbance state and the
// counters of input it refused (for posefaird's counters and STATUS=).
struct EstimatorState {
  bool initialised = false;     // an accelerometer reading has set the inclination
  Vec3 gyro_bias = Vec3::Zero();  // rad/s, estimated (zero for estimators without a bias model)
  double bias_sigma = 0.0;      // rad/s, the bias estimate's standard deviation (0: none kept)
  bool at_rest = false;         // rest detected (VQF)
  bool mag_disturbed = false;   // magnetic disturbance detected: heading updates held back (VQF)
  std::uint64_t updates = 0;         // samples taken
  std::uint64_t nonfinite = 0;       // readings left out for a NaN/inf component
  std::uint64_t gyro_saturated = 0;  // gyroscope readings at or beyond gyro_range
  std::uint64_t mag_stuck = 0;       // magnetometer readings left out as stuck
  std::uint64_t mag_absent = 0;      // samples without a magnetometer reading in 9D use
  std::uint64_t bad_time_steps = 0;  // samples ignored for dt <= 0 or not finite
  std::uint64_t gaps = 0;            // steps longer than max_gap, not integrated
  std::uint64_t state_resets = 0;    // non-finite states discarded
};

// The readings of one step after screening: a pointer is null when that reading is absent.
struct ImuStep {
  const Vec3* gyro = nullptr;   // rad/s
  const Vec3* accel = nullptr;  // m/s^2, non-zero
  const Vec3* mag = nullptr;    // any unit (directions and relative norms only)
  double dt = 0.0;              // seconds, > 0
  bool gyro_saturated = false;
};

// Options every estimator takes (their specs: common_estimator_options()).
struct EstimatorLimits {
  bool use_mag = true;          // false: 6D (accelerometer and gyroscope only), heading free
  double gyro_range = 34.9;     // rad/s (2000 deg/s): a reading at it is saturated
  double max_gap = 0.1;         // s: a longer step is a gap
  double mag_stuck_time = 0.5;  // s: an unchanged magnetometer vector this long is stuck
};

class OrientationEstimator {
 public:
  virtual ~OrientationEstimator() = default;
  virtual std::string_view name() const = 0;

  // One raw sample; dt is the time since the previous sample (ignored for the first).
  void update(const Sample& sample, double dt);

  // Sensor frame to ENU earth frame. Identity until initialised.
  const Quat& orientation() const { return q_; }
  const EstimatorState& state() const { return state_; }
  const EstimatorLimits& limits() const { return limits_; }

 protected:
  explicit OrientationEstimator(const EstimatorLimits& limits) : limits_(limits) {}
  // The first accelerometer reading (with the magnetometer's, if any): set q_ and any state.
  virtual void initialise(const Vec3& accel, const Vec3* mag);
  virtual void step(const ImuStep& in) = 0;
  // After a gap: the filters' memory of the motion before it no longer applies.
  virtual void after_gap() {}

  Quat q_ = Quat::Identity();
  EstimatorState state_;

 private:
  EstimatorLimits limits_;
  bool started_ = false;
  Vec3 last_gyro_ = Vec3::Zero();
  bool have_gyro_ = false;
  Vec3 last_mag_ = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  double mag_unchanged_for_ = 0.0;
};

// The orientation whose z axis is the accelerometer's (up) and, with a magnetometer reading not
// parallel to it, whose y axis is the horizontal part of the field (magnetic north); without
// one, the smallest rotation that levels the sensor (heading as the sensor's).
Quat orientation_from_accel_mag(const Vec3& accel, const Vec3* mag);

// A registered estimator.
struct OrientationEstimatorEntry {
  std::string_view name;
  std::string_view description;
  std::span<const OptionSpec> options;  // its own and the common ones
  std::unique_ptr<OrientationEstimator> (*make)(const OptionMap& options);
};

// The four options every estimator reads (magnetometer, gyro_range, max_gap, mag_stuck_time),
// to be listed in each entry's options, and their reading.
inline constexpr std::size_t kCommonEstimatorOptionCount = 4;
std::span<const OptionSpec, kCommonEstimatorOptionCount> common_estimator_options();
EstimatorLimits read_estimator_limits(const OptionReader& reader);

// `own` followed by the common options, for an entry's options table.
template <std::size_t N>
constexpr std::array<OptionSpec, N + kCommonEstimatorOptionCount> with_common_estimator_options(
    const std::array<OptionSpec, N>& own);

// The registry (estimator_registry.cpp): every entry in registration order (the first, vqf, is
// the default), one by name (nullptr when none), and every name.
std::span<const OrientationEstimatorEntry* const> orientation_estimator_entries();
const OrientationEstimatorEntry* find_orientation_estimator(std::string_view name);
std::vector<std::string> orientation_estimator_names();
// Builds `name` with `options`; throws OptionError naming the key for a bad value and
// std::invalid_argument for an unknown name (listing the known ones).
std::unique_ptr<OrientationEstimator> make_orientation_estimator(std::string_view name,
                                                                 const OptionMap& options);

// ---- implementation of the template ----
namespace detail {
inline constexpr std::array<OptionSpec, kCommonEstimatorOptionCount> kCommonEstimatorOptions{{
    {"magnetometer", OptionType::Boolean, "true",
     "use the magnetometer (9D); false: gyroscope and accelerometer only (6D), heading free"},
    {"gyro_range", OptionType::Float, "2000",
     "gyroscope range in deg/s: a reading at it is counted as saturated"},
    {"max_gap", OptionType::Float, "0.1", "seconds: a longer time step is a gap, not integrated"},
    {"mag_stuck_time", OptionType::Float, "0.5",
     "seconds an unchanged magnetometer vector may repeat before it is left out as stuck"},
}};
}  // namespace detail

template <std::size_t N>
constexpr std::array<OptionSpec, N + kCommonEstimatorOptionCount> with_common_estimator_options(
    const std::array<OptionSpec, N>& own) {
  std::array<OptionSpec, N + kCommonEstimatorOptionCount> all{};
  for (std::size_t i = 0; i < N; ++i) all[i] = own[i];
  for (std::size_t i = 0; i < kCommonEstimatorOptionCount; ++i)
    all[N + i] = detail::kCommonEstimatorOptions[i];
  return all;
}

}  // namespace posefair
