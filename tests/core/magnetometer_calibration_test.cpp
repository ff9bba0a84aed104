// Magnetometer hard/soft-iron calibration: readings on a known ellipsoid give back its offset
// and a correction that makes every reading the same length; too little data is refused.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "posefair/core/magnetometer_calibration.hpp"

namespace posefair {
namespace {

using ::testing::HasSubstr;

TEST(MagnetometerCalibration, RecoversHardAndSoftIron) {
  const Vec3 offset(12.0, -7.5, 30.0);
  Eigen::Matrix3d distortion;  // soft iron: the sensor sees distortion * true field
  distortion << 1.10, 0.05, -0.02, 0.05, 0.92, 0.03, -0.02, 0.03, 1.03;
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  std::vector<Vec3> readings;
  for (int k = 0; k < 400; ++k) {
    const Vec3 field = Vec3(normal(rng), normal(rng), normal(rng)).normalized() * 48.0;
    readings.push_back(distortion * field + offset);
  }
  const MagnetometerCalibration cal = fit_magnetometer_calibration(readings);
  EXPECT_LT((cal.offset - offset).norm(), 1e-6);
  EXPECT_LT(cal.residual_rms, 1e-6);
  for (const Vec3& m : readings) EXPECT_NEAR(cal.apply(m).norm(), cal.field_strength, 1e-6);
  // The correction undoes the distortion up to a rotation and the mean radius.
  const Eigen::Matrix3d undone = cal.soft_iron * distortion * (48.0 / cal.field_strength);
  EXPECT_LT((undone.transpose() * undone - Eigen::Matrix3d::Identity()).norm(), 1e-6);
}

TEST(MagnetometerCalibration, RefusesDataThatDoesNotDetermineAnEllipsoid) {
  std::vector<Vec3> few(5, Vec3(1, 2, 3));
  EXPECT_THAT([&] { fit_magnetometer_calibration(few); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("at least 9 readings")));
  std::vector<Vec3> flat;  // turned about one axis only: a circle, not an ellipsoid
  for (int k = 0; k < 100; ++k) flat.emplace_back(40.0 * std::cos(0.1 * k), 40.0 * std::sin(0.1 * k), 5.0);
  EXPECT_THAT([&] { fit_magnetometer_calibration(flat); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("turn the sensor")));
  std::vector<Vec3> bad(20, Vec3(1, 2, 3));
  bad[3].x() = std::nan("");
  EXPECT_THROW(fit_magnetometer_calibration(bad), std::invalid_argument);
}

}  // namespace
}  // namespace posefair
