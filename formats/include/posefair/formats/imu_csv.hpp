#pragma once
// Raw inertial recordings in CSV, as BROAD publishes them (docs/fusion.md): one row per IMU
// sample, columns found by name (case-insensitive) in a header line:
//   time         t, time, timestamp or t_s (seconds; required, must not decrease)
//   gyroscope    gyr_x.. or gyro_x.. (any suffix): rad/s, or deg/s with a `_dps` suffix
//   accelerometer acc_x.. or accel_x..: m/s², or g with a `_g` suffix
//   magnetometer mag_x..: µT, or nT with `_nt`, gauss with `_gauss` (optional)
//   reference    gt_qw..gt_qz or qw..qz (optional): the true orientation, sensor to world
//   movement     movement (optional, 0/1): BROAD's motion phases, where errors are scored
// Each row becomes one Sample with kHasGyro/kHasAccel/kHasMag set for the readings present;
// a reading with a `nan` or empty field is left out of that sample (its flag clear) and
// counted, never guessed. The reference, when present and not `nan`, is the sample's
// orientation; otherwise the sample is kNoOrientation.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "posefair/core/sample.hpp"

namespace posefair::formats {

struct ImuRecording {
  std::vector<Sample> samples;          // time = device time = the time column
  std::vector<std::uint8_t> movement;   // one per sample; all 1 when the file has no column
  bool has_mag_column = false;
  bool has_reference_column = false;
  std::size_t missing_readings = 0;     // gyro/accel/mag triples left out for a nan or empty field
};

// Throws PoseFileError ("<name>:<line>: ...") for a missing required column, a row with the
// wrong number of fields, a field that is not a number, or time going backwards.
ImuRecording parse_imu_csv(const std::string& text, const std::string& name);
ImuRecording read_imu_csv(const std::filesystem::path& path);

}  // namespace posefair::formats
