// The orientation estimators (VQF, Madgwick, Mahony) on synthetic recordings with a known true
// orientation: convergence in 9D and 6D, VQF's bias estimation at rest and in motion, its
// magnetic disturbance rejection, and the registry.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "imu_test_motion.hpp"
#include "posefair/core/orientation_error.hpp"
#include "posefair/core/orientation_estimator.hpp"
#include "posefair/core/vqf_estimator.hpp"

namespace posefair {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using test::ImuRecordingSpec;
using test::make_synthetic_imu;
using test::SyntheticImu;

constexpr double kEstimatorTestDeg = M_PI / 180.0;

// The worst total / inclination error over the samples from `from_seconds` on, in degrees.
struct WorstSyntheticError {
  double total = 0.0, inclination = 0.0, heading = 0.0;
};

WorstSyntheticError run_worst_error(OrientationEstimator& e, const SyntheticImu& imu, double from_seconds) {
  WorstSyntheticError worst;
  for (std::size_t k = 0; k < imu.samples.size(); ++k) {
    e.update(imu.samples[k], imu.dt);
    if (imu.samples[k].time < from_seconds) continue;
    const OrientationError err = earth_frame_error(e.orientation(), imu.truth[k]);
    worst.total = std::max(worst.total, err.total / kEstimatorTestDeg);
    worst.inclination = std::max(worst.inclination, err.inclination / kEstimatorTestDeg);
    worst.heading = std::max(worst.heading, err.heading / kEstimatorTestDeg);
  }
  return worst;
}

std::unique_ptr<OrientationEstimator> make_estimator_for_test(std::string_view name, OptionMap options = {}) {
  return make_orientation_estimator(name, options);
}

TEST(OrientationEstimator, InitialOrientationFromAccelerometerAndMagnetometer) {
  const Quat truth = so3::from_rotation_vector(Vec3(0.3, -0.5, 2.0));
  const Vec3 acc = truth.conjugate() * test::kGravityUp, mag = truth.conjugate() * test::kEarthField;
  EXPECT_LT(so3::rotation_angle(orientation_from_accel_mag(acc, &mag), truth), 1e-12);
  // Without the field: level, heading free.
  EXPECT_LT(earth_frame_error(orientation_from_accel_mag(acc, nullptr), truth).inclination, 1e-12);
}

TEST(OrientationEstimator, EveryEstimatorTracksTheTrueOrientationIn9D) {
  ImuRecordingSpec spec;
  spec.gyro_noise = 0.005;
  spec.accel_noise = 0.05;
  spec.mag_noise = 0.3;
  spec.start = so3::from_rotation_vector(Vec3(0.4, 0.2, 1.0));
  const SyntheticImu imu = make_synthetic_imu(spec);
  for (const char* name : {"vqf", "madgwick", "mahony"}) {
    SCOPED_TRACE(name);
    auto e = make_estimator_for_test(name);
    EXPECT_EQ(e->name(), name);
    const WorstSyntheticError worst = run_worst_error(*e, imu, 2.0);
    EXPECT_LT(worst.total, 3.0);
    EXPECT_TRUE(e->state().initialised);
    EXPECT_EQ(e->state().updates, imu.samples.size());
  }
}

TEST(OrientationEstimator, SixDKeepsInclinationAndIgnoresTheMagnetometer) {
  ImuRecordingSpec spec;
  spec.gyro_noise = 0.005;
  const SyntheticImu imu = make_synthetic_imu(spec);
  SyntheticImu rotated_field = imu;
  for (Sample& s : rotated_field.samples) s.mag = Vec3(s.mag.z(), -s.mag.x(), s.mag.y());
  for (const char* name : {"vqf", "madgwick", "mahony"}) {
    SCOPED_TRACE(name);
    auto a = make_estimator_for_test(name, {{"magnetometer", false}});
    auto b = make_estimator_for_test(name, {{"magnetometer", false}});
    EXPECT_LT(run_worst_error(*a, imu, 2.0).inclination, 2.0);
    run_worst_error(*b, rotated_field, 0.0);
    EXPECT_EQ(a->orientation().coeffs(), b->orientation().coeffs());
    EXPECT_EQ(a->state().mag_absent, 0u);  // 6D by choice is not a missing magnetometer
  }
}

TEST(OrientationEstimator, VqfEstimatesTheGyroscopeBiasAtRest) {
  ImuRecordingSpec spec;
  spec.seconds = 12.0;
  spec.rest_seconds = 12.0;
  spec.gyro_bias = Vec3(0.6, -0.4, 0.3) * kEstimatorTestDeg;
  spec.gyro_noise = 0.002;
  const SyntheticImu imu = make_synthetic_imu(spec);
  auto e = make_estimator_for_test("vqf");
  run_worst_error(*e, imu, 0.0);
  EXPECT_TRUE(e->state().at_rest);
  EXPECT_LT((e->state().gyro_bias - spec.gyro_bias).norm() / kEstimatorTestDeg, 0.05);
  EXPECT_LT(e->state().bias_sigma / kEstimatorTestDeg, 0.1);
}

TEST(OrientationEstimator, VqfEstimatesTheGyroscopeBiasInMotionAndIsMoreAccurateForIt) {
  ImuRecordingSpec spec;
  spec.seconds = 60.0;
  spec.gyro_bias = Vec3(0.8, -0.6, 0.5) * kEstimatorTestDeg;
  spec.gyro_noise = 0.003;
  spec.accel_noise = 0.05;
  const SyntheticImu imu = make_synthetic_imu(spec);
  auto with = make_estimator_for_test("vqf", {{"magnetometer", false}});
  auto without = make_estimator_for_test("vqf", {{"magnetometer", false}, {"motion_bias", false}, {"rest_bias", false}});
  const double err_with = run_worst_error(*with, imu, 40.0).inclination;
  const double err_without = run_worst_error(*without, imu, 40.0).inclination;
  EXPECT_FALSE(with->state().at_rest);
  const Vec3 error = with->state().gyro_bias - spec.gyro_bias;
  EXPECT_LT(error.norm(), 0.5 * spec.gyro_bias.norm());  // learned in motion, without rest
  EXPECT_LT(err_with, err_without);
}

TEST(OrientationEstimator, VqfRejectsAMagneticDisturbanceThatMadgwickFollows) {
  ImuRecordingSpec spec;
  spec.seconds = 40.0;
  spec.mag_noise = 0.2;
  SyntheticImu imu = make_synthetic_imu(spec);
  // A magnet near the sensor from 25 s to 32 s: 30 µT more field, fixed in the earth frame.
  for (std::size_t k = 0; k < imu.samples.size(); ++k)
    if (imu.samples[k].time >= 25.0 && imu.samples[k].time < 32.0)
      imu.samples[k].mag += imu.truth[k].conjugate() * Vec3(30.0, 0.0, 0.0);
  auto vqf = make_estimator_for_test("vqf");
  auto madgwick = make_estimator_for_test("madgwick");
  bool disturbed_seen = false;
  double vqf_worst = 0.0, madgwick_worst = 0.0;
  for (std::size_t k = 0; k < imu.samples.size(); ++k) {
    vqf->update(imu.samples[k], imu.dt);
    madgwick->update(imu.samples[k], imu.dt);
    if (imu.samples[k].time >= 26.0 && imu.samples[k].time < 32.0) disturbed_seen |= vqf->state().mag_disturbed;
    if (imu.samples[k].time < 25.0) continue;
    vqf_worst = std::max(vqf_worst, earth_frame_error(vqf->orientation(), imu.truth[k]).heading / kEstimatorTestDeg);
    madgwick_worst = std::max(madgwick_worst, earth_frame_error(madgwick->orientation(), imu.truth[k]).heading / kEstimatorTestDeg);
  }
  EXPECT_TRUE(disturbed_seen);
  EXPECT_FALSE(vqf->state().mag_disturbed);  // over once the magnet is gone
  EXPECT_LT(vqf_worst, 3.0);
  EXPECT_GT(madgwick_worst, 3.0 * vqf_worst);
}

TEST(OrientationEstimatorRegistry, ListsBuildsAndJudgesOptions) {
  EXPECT_THAT(orientation_estimator_names(), ElementsAre("madgwick", "mahony", "vqf"));
  EXPECT_EQ(orientation_estimator_entries().front()->name, "vqf");  // the default
  for (const OrientationEstimatorEntry* e : orientation_estimator_entries()) {
    SCOPED_TRACE(e->name);
    EXPECT_FALSE(e->description.empty());
    for (const OptionSpec& common : common_estimator_options())
      EXPECT_NE(find_option(e->options, common.name), nullptr);
    EXPECT_NE(e->make({}), nullptr);
  }
  try {
    make_estimator_for_test("kalman");
    ADD_FAILURE() << "no error for an unknown estimator";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("unknown estimator 'kalman' (known: madgwick, mahony, vqf)"));
  }
  const auto key_of = [](std::string_view name, OptionMap options) -> std::string {
    try {
      make_estimator_for_test(name, std::move(options));
    } catch (const OptionError& e) {
      return e.key();
    }
    return "no error";
  };
  EXPECT_EQ(key_of("madgwick", {{"beta", -0.1}}), "beta");
  EXPECT_EQ(key_of("mahony", {{"ki", -1.0}}), "ki");
  EXPECT_EQ(key_of("vqf", {{"tau_acc", 0.0}}), "tau_acc");
  EXPECT_EQ(key_of("vqf", {{"max_gap", 0.0}}), "max_gap");
  EXPECT_EQ(key_of("vqf", {{"gyro_range", -5.0}}), "gyro_range");
  EXPECT_EQ(key_of("vqf", {{"beta", 0.1}}), "beta");  // not a VQF option
}

}  // namespace
}  // namespace posefair
