// BROAD's error measures on rotations whose errors are known exactly, and its RMSE mask.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "posefair/core/orientation_error.hpp"

namespace posefair {
namespace {

constexpr double kErrorTestDeg = M_PI / 180.0;

Quat rotation_about(const Vec3& axis, double degrees) { return Quat(Eigen::AngleAxisd(degrees * kErrorTestDeg, axis.normalized())); }

TEST(OrientationError, SplitsTheEarthFrameErrorIntoHeadingAndInclination) {
  const Quat ref = rotation_about(Vec3(1, 2, 3), 70.0);
  // An error about the vertical is all heading.
  OrientationError e = earth_frame_error(rotation_about(Vec3::UnitZ(), 10.0) * ref, ref);
  EXPECT_NEAR(e.total / kErrorTestDeg, 10.0, 1e-9);
  EXPECT_NEAR(e.heading / kErrorTestDeg, 10.0, 1e-9);
  EXPECT_NEAR(e.inclination, 0.0, 1e-7);
  // An error about a horizontal earth axis is all inclination (applied on the earth side).
  e = earth_frame_error(rotation_about(Vec3(1, 1, 0), 4.0) * ref, ref);
  EXPECT_NEAR(e.total / kErrorTestDeg, 4.0, 1e-9);
  EXPECT_NEAR(e.inclination / kErrorTestDeg, 4.0, 1e-9);
  EXPECT_NEAR(e.heading, 0.0, 1e-12);
  // The sign of a quaternion does not matter.
  const Quat est = rotation_about(Vec3::UnitZ(), -30.0) * ref;
  EXPECT_NEAR(earth_frame_error(Quat(-est.coeffs()), ref).total / kErrorTestDeg, 30.0, 1e-9);
}

TEST(OrientationError, RmseOverTheScoredSamplesOnly) {
  const Quat ref = Quat::Identity();
  const std::vector<Quat> est = {rotation_about(Vec3::UnitZ(), 3.0), rotation_about(Vec3::UnitZ(), 4.0), rotation_about(Vec3::UnitX(), 90.0)};
  const std::vector<Quat> refs(3, ref);
  const std::vector<std::uint8_t> scored = {1, 1, 0};
  const OrientationRmse r = orientation_rmse(est, refs, scored);
  EXPECT_EQ(r.samples, 2u);
  EXPECT_NEAR(r.total_deg, std::sqrt((9.0 + 16.0) / 2.0), 1e-9);
  EXPECT_NEAR(r.heading_deg, r.total_deg, 1e-9);
  EXPECT_NEAR(r.inclination_deg, 0.0, 1e-5);
  EXPECT_TRUE(std::isnan(orientation_rmse(est, refs, std::vector<std::uint8_t>(3, 0)).total_deg));
  EXPECT_THROW(orientation_rmse(est, refs, std::vector<std::uint8_t>(2, 1)), std::invalid_argument);
}

}  // namespace
}  // namespace posefair
