// Bad input to the orientation estimators: NaN readings, a saturated gyroscope, a stuck or
// absent magnetometer, bad time steps and a gap. Each is counted, and the estimate stays
// finite and comes back to the truth.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "imu_test_motion.hpp"
#include "posefair/core/orientation_error.hpp"
#include "posefair/core/orientation_estimator.hpp"

namespace posefair {
namespace {

using test::ImuRecordingSpec;
using test::make_synthetic_imu;
using test::SyntheticImu;

constexpr double kRobustnessDeg = M_PI / 180.0;
constexpr double kRobustnessNaN = std::numeric_limits<double>::quiet_NaN();

class EstimatorRobustness : public ::testing::TestWithParam<const char*> {
 protected:
  std::unique_ptr<OrientationEstimator> make(OptionMap options = {}) {
    return make_orientation_estimator(GetParam(), options);
  }
  static SyntheticImu imu(double seconds = 20.0) {
    ImuRecordingSpec spec;
    spec.seconds = seconds;
    spec.gyro_noise = 0.003;
    spec.accel_noise = 0.03;
    spec.mag_noise = 0.2;
    return make_synthetic_imu(spec);
  }
  // Runs every sample through `edit` first; returns the total error at the end, in degrees.
  template <class Edit>
  static double run(OrientationEstimator& e, const SyntheticImu& m, Edit edit, double dt_override_at = -1.0,
                    double dt_override = 0.0) {
    for (std::size_t k = 0; k < m.samples.size(); ++k) {
      Sample s = m.samples[k];
      edit(s);
      const bool override_here = dt_override_at >= 0.0 && std::abs(s.time - dt_override_at) < 0.5 * m.dt;
      e.update(s, override_here ? dt_override : m.dt);
      EXPECT_TRUE(e.orientation().coeffs().allFinite());
      EXPECT_NEAR(e.orientation().norm(), 1.0, 1e-9);
    }
    return earth_frame_error(e.orientation(), m.truth.back()).total / kRobustnessDeg;
  }
};

TEST_P(EstimatorRobustness, NaNReadingsAreLeftOutAndCounted) {
  const SyntheticImu m = imu();
  auto e = make();
  const double err = run(*e, m, [](Sample& s) {
    if (s.sequence % 50 == 7) s.gyro.x() = kRobustnessNaN;
    if (s.sequence % 50 == 17) s.accel.z() = kRobustnessNaN;
    if (s.sequence % 50 == 27) s.mag.y() = std::numeric_limits<double>::infinity();
  });
  EXPECT_EQ(e->state().nonfinite, 3u * (m.samples.size() / 50));
  EXPECT_EQ(e->state().state_resets, 0u);
  EXPECT_LT(err, 3.0);
}

TEST_P(EstimatorRobustness, ASaturatedGyroscopeIsCountedAndTheEstimateRecovers) {
  const SyntheticImu m = imu(30.0);
  auto e = make({{"gyro_range", 100.0}});  // deg/s, above the synthetic motion (69 deg/s at most)
  const double err = run(*e, m, [](Sample& s) {
    if (s.time > 10.0 && s.time < 12.0) s.gyro.x() = 100.0 * kRobustnessDeg;  // pinned at full scale for 2 s
  });
  EXPECT_NEAR(static_cast<double>(e->state().gyro_saturated), 400.0, 1.0);
  EXPECT_TRUE(e->state().gyro_bias.allFinite());
  EXPECT_LT(e->state().gyro_bias.cwiseAbs().maxCoeff() / kRobustnessDeg, 0.2);  // the pinned reading taught no bias
  EXPECT_LT(err, 4.0);
}

TEST_P(EstimatorRobustness, AStuckMagnetometerIsLeftOut) {
  const SyntheticImu m = imu();
  auto e = make();
  Vec3 frozen = Vec3::Zero();
  const double err = run(*e, m, [&](Sample& s) {
    if (s.time < 8.0) return;
    if (frozen.isZero()) frozen = s.mag;
    if (s.time < 12.0) s.mag = frozen;  // the chip stopped updating while the sensor turned
  });
  // 4 s frozen at 200 Hz, left out after mag_stuck_time (0.5 s).
  EXPECT_NEAR(static_cast<double>(e->state().mag_stuck), 3.5 * 200.0, 2.0);
  EXPECT_LT(err, 3.0);
}

TEST_P(EstimatorRobustness, AnAbsentMagnetometerIsCountedAnd6DGoesOn) {
  const SyntheticImu m = imu();
  auto e = make();
  run(*e, m, [](Sample& s) {
    if (s.time > 5.0) s.flags &= ~static_cast<std::uint32_t>(kHasMag);
  });
  std::size_t without = 0;
  for (const Sample& s : m.samples) without += s.time > 5.0 ? 1 : 0;
  EXPECT_EQ(e->state().mag_absent, without);
  EXPECT_LT(earth_frame_error(e->orientation(), m.truth.back()).inclination / kRobustnessDeg, 2.0);
}

TEST_P(EstimatorRobustness, BadTimeStepsAreIgnoredAndCounted) {
  const SyntheticImu m = imu();
  auto e = make();
  // Feed three bad steps on top of the recording; the good samples alone carry the motion.
  for (std::size_t k = 0; k < m.samples.size(); ++k) {
    e->update(m.samples[k], m.dt);
    if (k == 300) e->update(m.samples[k], 0.0);
    if (k == 301) e->update(m.samples[k], -0.01);
    if (k == 302) e->update(m.samples[k], kRobustnessNaN);
  }
  EXPECT_EQ(e->state().bad_time_steps, 3u);
  EXPECT_LT(earth_frame_error(e->orientation(), m.truth.back()).total / kRobustnessDeg, 3.0);
}

TEST_P(EstimatorRobustness, AGapIsNotIntegratedAndTheEstimateReconverges) {
  const SyntheticImu m = imu(30.0);
  auto e = make();
  // Samples between 10 s and 11 s are lost: the next one comes 1 s after the last.
  std::size_t taken = 0;
  double previous = 0.0;
  for (std::size_t k = 0; k < m.samples.size(); ++k) {
    const Sample& s = m.samples[k];
    if (s.time > 10.0 && s.time < 11.0) continue;
    e->update(s, taken == 0 ? 0.0 : s.time - previous);
    previous = s.time;
    ++taken;
  }
  EXPECT_EQ(e->state().gaps, 1u);
  EXPECT_LT(earth_frame_error(e->orientation(), m.truth.back()).inclination / kRobustnessDeg, 2.0);
  EXPECT_LT(earth_frame_error(e->orientation(), m.truth.back()).total / kRobustnessDeg, 5.0);
}

TEST_P(EstimatorRobustness, NothingHappensBeforeTheFirstAccelerometerReading) {
  ImuRecordingSpec clean;
  clean.seconds = 1.0;
  const SyntheticImu m = make_synthetic_imu(clean);
  auto e = make();
  Sample gyro_only = m.samples[0];
  gyro_only.flags = kHasGyro | kNoOrientation;
  e->update(gyro_only, 0.0);
  EXPECT_FALSE(e->state().initialised);
  EXPECT_EQ(e->orientation().coeffs(), Quat::Identity().coeffs());
  e->update(m.samples[0], m.dt);
  EXPECT_TRUE(e->state().initialised);
  EXPECT_LT(so3::rotation_angle(e->orientation(), m.truth[0]), 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Estimators, EstimatorRobustness, ::testing::Values("vqf", "madgwick", "mahony"));

}  // namespace
}  // namespace posefair
