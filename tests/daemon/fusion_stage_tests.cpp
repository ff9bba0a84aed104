// [stream.fusion]'s stage (daemon/…/fusion_stage.hpp): raw samples get the estimator's
// orientation, samples with one pass unchanged, nothing goes on before the first
// accelerometer reading, and the estimator's counters show through.
#include <gtest/gtest.h>

#include <cmath>

#include "posefair/daemon/fusion_stage.hpp"

namespace posefair::daemon {
namespace {

Sample raw_at_rest(double t) {
  Sample s;
  s.time = t;
  s.gyro = Vec3(0.001, -0.002, 0.0005);
  s.accel = Vec3(0.0, 9.81 * std::sin(0.2), 9.81 * std::cos(0.2));  // tilted 0.2 rad about x
  s.mag = Vec3(0.0, 20.0, -40.0);
  s.flags = kHasGyro | kHasAccel | kHasMag | kNoOrientation;
  return s;
}

TEST(FusionStage, RawSamplesGetTheEstimatorsOrientation) {
  FusionStage stage(FusionConfig{"vqf", {}});
  Sample s;
  for (int k = 0; k < 400; ++k) {
    s = raw_at_rest(0.005 * k);
    ASSERT_TRUE(stage.apply(s));
    EXPECT_TRUE(s.has_orientation());
  }
  // The estimate's up, seen from the sensor, is where the accelerometer says (within 0.3°: the
  // small gyroscope bias of these samples is being learned).
  const Vec3 up_in_sensor = s.orientation.conjugate() * Vec3::UnitZ();
  EXPECT_LT((up_in_sensor - s.accel.normalized()).norm(), 5e-3);
  EXPECT_EQ(stage.state().updates, 400u);
  EXPECT_EQ(stage.waiting(), 0u);
}

TEST(FusionStage, OrientedSamplesPassAndNothingGoesOnBeforeTheFirstAccelerometerReading) {
  FusionStage stage(FusionConfig{"mahony", {{"magnetometer", false}}});
  Sample oriented;
  oriented.orientation = Quat(0.5, 0.5, 0.5, 0.5);
  ASSERT_TRUE(stage.apply(oriented));
  EXPECT_EQ(oriented.orientation.coeffs(), Quat(0.5, 0.5, 0.5, 0.5).coeffs());
  Sample gyro_only = raw_at_rest(0.0);
  gyro_only.flags = kHasGyro | kNoOrientation;
  EXPECT_FALSE(stage.apply(gyro_only));
  EXPECT_EQ(stage.waiting(), 1u);
  Sample nan = raw_at_rest(0.005);
  nan.accel.x() = std::nan("");
  EXPECT_FALSE(stage.apply(nan));  // its accelerometer reading is left out: still nothing to start from
  EXPECT_EQ(stage.state().nonfinite, 1u);
  Sample good = raw_at_rest(0.010);
  EXPECT_TRUE(stage.apply(good));
  EXPECT_EQ(stage.state().mag_absent, 0u);  // 6D by configuration
}

}  // namespace
}  // namespace posefair::daemon
