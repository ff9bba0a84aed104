// Raw IMU CSV (BROAD's columns): readings into Sample fields with their flags, units by
// suffix, the reference quaternion and movement flag, missing readings, bad input with line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "posefair/formats/imu_csv.hpp"
#include "posefair/formats/pose_file.hpp"

namespace posefair::formats {
namespace {

using ::testing::HasSubstr;

// BROAD trial 07, rows 782-891: 10 without optical data, then 100 tracked (tests/data/broad/README.md).
const std::string kBroadImuExcerpt = POSEFAIR_SOURCE_DIR "/tests/data/broad/07_undisturbed_fast_rotation_B.csv";

std::string imu_error_of(const std::string& text) {
  try {
    parse_imu_csv(text, "imu.csv");
  } catch (const PoseFileError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ImuCsv, ReadsTheBroadExcerptIntoRawSamples) {
  const ImuRecording rec = read_imu_csv(kBroadImuExcerpt);
  ASSERT_EQ(rec.samples.size(), 110u);
  EXPECT_TRUE(rec.has_mag_column);
  EXPECT_TRUE(rec.has_reference_column);
  EXPECT_EQ(rec.missing_readings, 0u);
  const Sample& first = rec.samples.front();
  EXPECT_DOUBLE_EQ(first.time, 2.7335);
  EXPECT_TRUE(first.has_gyro() && first.has_accel() && first.has_mag());
  EXPECT_FALSE(first.has_orientation());  // the optical system had not found the marker yet
  EXPECT_EQ(first.gyro, Vec3(0.00532674488, -6.52338106e-19, -0.00532674488));
  EXPECT_EQ(first.accel, Vec3(0.105656288, 0.0364162123, 9.76883813));
  EXPECT_EQ(first.mag, Vec3(0.405826149, 17.6822379, -40.6079524));
  const Sample& tracked = rec.samples[10];
  ASSERT_TRUE(tracked.has_orientation());
  EXPECT_NEAR(tracked.orientation.w(), 0.9999256, 1e-7);
  EXPECT_NEAR(tracked.orientation.z(), -0.0119716909, 1e-9);
  std::size_t with_reference = 0;
  for (const Sample& s : rec.samples) with_reference += s.has_orientation() ? 1 : 0;
  EXPECT_EQ(with_reference, 100u);
  EXPECT_EQ(rec.movement.size(), 110u);
  EXPECT_EQ(rec.movement[0], 0);  // the excerpt lies in the rest before the motion phase
  EXPECT_EQ(rec.samples.back().sequence, 109u);
}

TEST(ImuCsv, UnitsBySuffixMovementAndOptionalColumns) {
  const ImuRecording rec = parse_imu_csv(
      "time,gyro_x_dps,gyro_y_dps,gyro_z_dps,accel_x_g,accel_y_g,accel_z_g,movement\n"
      "0.0,180,0,-90,0,0,1,0\n"
      "0.01,0,0,0,0.5,0,0,1\n",
      "imu.csv");
  ASSERT_EQ(rec.samples.size(), 2u);
  EXPECT_FALSE(rec.has_mag_column);
  EXPECT_FALSE(rec.samples[0].has_mag());
  EXPECT_NEAR(rec.samples[0].gyro.x(), M_PI, 1e-15);
  EXPECT_NEAR(rec.samples[0].gyro.z(), -M_PI / 2, 1e-15);
  EXPECT_DOUBLE_EQ(rec.samples[0].accel.z(), 9.80665);
  EXPECT_EQ(rec.movement, (std::vector<std::uint8_t>{0, 1}));
}

TEST(ImuCsv, AMissingReadingClearsOnlyItsFlag) {
  const ImuRecording rec = parse_imu_csv(
      "t,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z,mag_x,mag_y,mag_z\n"
      "0,1,2,3,0,0,9.8,nan,1,2\n"
      "1,,2,3,0,0,9.8,20,1,2\n",
      "imu.csv");
  ASSERT_EQ(rec.samples.size(), 2u);
  EXPECT_TRUE(rec.samples[0].has_gyro());
  EXPECT_FALSE(rec.samples[0].has_mag());
  EXPECT_FALSE(rec.samples[1].has_gyro());
  EXPECT_TRUE(rec.samples[1].has_mag());
  EXPECT_TRUE(rec.samples[1].has_accel());
  EXPECT_EQ(rec.missing_readings, 2u);
}

TEST(ImuCsv, BadInputNamesTheLine) {
  EXPECT_THAT(imu_error_of("t,qw,qx,qy,qz\n0,1,0,0,0\n"), HasSubstr("imu.csv:1: missing columns"));
  EXPECT_THAT(imu_error_of("t,gyr_x,gyr_y,acc_x,acc_y,acc_z\n"), HasSubstr("incomplete column set gyr_"));
  EXPECT_THAT(imu_error_of("t,gyr_x_rads,gyr_y_rads,gyr_z_dps,acc_x,acc_y,acc_z\n"),
              HasSubstr("different units"));
  EXPECT_THAT(imu_error_of("t,gyr_x_furlong,gyr_y_furlong,gyr_z_furlong,acc_x,acc_y,acc_z\n"),
              HasSubstr("unknown unit 'furlong'"));
  const std::string header = "t,gyr_x,gyr_y,gyr_z,acc_x,acc_y,acc_z\n";
  EXPECT_THAT(imu_error_of(header + "0,1,2,3,4,5,6\n1,1,2,x,4,5,6\n"),
              HasSubstr("imu.csv:3: field 4 (gyr_z) 'x' is not a number"));
  EXPECT_THAT(imu_error_of(header + "0,1,2,3,4,5\n"), HasSubstr("imu.csv:2: expected 7 fields"));
  EXPECT_THAT(imu_error_of(header + "1,1,2,3,4,5,6\n0,1,2,3,4,5,6\n"), HasSubstr("imu.csv:3: time goes backwards"));
  EXPECT_THAT(imu_error_of(header), HasSubstr("no samples"));
}

}  // namespace
}  // namespace posefair::formats
