// Camera matrices (eqs. 4-5) and camera keyframe interpolation (eq. 7) incl. centre of
// projection and skew changes.
#include <cmath>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "posefair/core/camera_matrix.hpp"

namespace posefair {
namespace {

Eigen::Vector2d project(const Mat4& c, const Eigen::Vector3d& p) {
  const Eigen::Vector4d h = c * Eigen::Vector4d(p.x(), p.y(), p.z(), 1.0);
  return h.head<2>() / h.w();
}

CameraParams camera(Eigen::Vector3d from, Eigen::Vector3d at) {
  CameraParams c;
  c.from = from;
  c.at = at;
  c.lens.fov_y = 50.0 * std::numbers::pi / 180.0;
  return c;
}

TEST(CameraMatrix, PerspectiveSplitsAsEq5) {
  CameraIntrinsics l;
  l.aspect = 0.75;
  l.skew = 0.1;
  l.cop_u = 0.2;
  l.cop_v = -0.3;
  l.near = 0.5;
  l.far = 50.0;
  const double k = 0.01;
  Mat4 p;  // eq. 4 as printed
  p << 0.75, 0.1, 0.2, 0, 0, 1, -0.3, 0, 0, 0, -1 / (1 + k), k / (1 + k), 0, 0, -1, 0;
  EXPECT_LT((perspective_matrix(l) - p).norm(), 1e-15);
  EXPECT_LT((perspective_a(k) * perspective_b(l) - p).norm(), 1e-15);
}

TEST(CameraMatrix, LooksAtTheTargetAndSpansTheFieldOfView) {
  CameraParams c = camera({3, 1, 4}, {0, 0.5, -1});
  EXPECT_LT(project(camera_matrix(c), c.at).norm(), 1e-12);
  // A point on the upper edge of the vertical field of view, 2 units ahead.
  const Eigen::Matrix3d r = look_at_rotation(c.from, c.at, c.up);
  const Eigen::Vector3d ahead = -r.row(2).transpose(), up = r.row(1).transpose();
  const Eigen::Vector3d edge = c.from + 2.0 * ahead + 2.0 * std::tan(c.lens.fov_y / 2) * up;
  EXPECT_NEAR(project(camera_matrix(c), edge).y(), 1.0, 1e-12);
  // The centre of projection shifts the image: the target lands at (-u0, -v0).
  c.lens.cop_u = 0.25;
  c.lens.cop_v = -0.1;
  EXPECT_LT((project(camera_matrix(c), c.at) - Eigen::Vector2d(-0.25, 0.1)).norm(), 1e-12);
  EXPECT_THROW(look_at_rotation({0, 0, 0}, {0, 0, 0}, {0, 1, 0}), std::invalid_argument);
  EXPECT_THROW(look_at_rotation({0, 0, 0}, {0, 5, 0}, {0, 1, 0}), std::invalid_argument);
}

// With alpha = 1, P_b = I + N. A change of the centre of projection alone, or of the skew alone,
// has N^2 = 0, so log P_b = N and the change is interpolated exactly linearly. (Both at once
// give N^2 = gamma v0 e0 e2^T != 0: then the interpolation is not linear in the parameters.)
void expect_linear_lens_change(double u, double v, double skew) {
  CameraParams a = camera({0, 0, 5}, {0, 0, 0}), b = a;
  b.lens.cop_u = u;
  b.lens.cop_v = v;
  b.lens.skew = skew;
  const std::vector<CameraKey> keys{camera_key(a), camera_key(b)};
  const std::vector<double> times{0, 1}, frames{0, 0.25, 0.5, 1};
  const auto r = interpolate_cameras(InterpolationMethod::Linear, times, keys, frames, CombinationOptions::precise());
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_LT((r.value()[0] - camera_matrix(a)).norm(), 1e-9);
  EXPECT_LT((r.value()[3] - camera_matrix(b)).norm(), 1e-6);
  // P_b with alpha = 1 is I + N, N^2 = 0: its logarithm is N, so u0, v0, gamma move linearly.
  for (std::size_t f = 1; f < 3; ++f) {
    CameraParams m = a;
    m.lens.cop_u = u * frames[f];
    m.lens.cop_v = v * frames[f];
    m.lens.skew = skew * frames[f];
    EXPECT_LT((r.value()[f] - camera_matrix(m)).norm(), 1e-6) << f;
  }
}

TEST(CameraInterpolation, ReproducesTheKeysAndInterpolatesCentreOfProjectionOrSkewLinearly) {
  expect_linear_lens_change(0.4, -0.2, 0.0);
  expect_linear_lens_change(0.0, 0.0, 0.3);
}

TEST(CameraInterpolation, KeepsALookedAtPointNearTheCentreWhileOrbiting) {
  // Four keys orbiting the origin by 25 degrees each, all looking at it (any 4 within 90).
  std::vector<CameraKey> keys;
  std::vector<double> times;
  for (int i = 0; i < 4; ++i) {
    const double th = i * 25.0 * std::numbers::pi / 180.0;
    keys.push_back(camera_key(camera({5 * std::sin(th), 1, 5 * std::cos(th)}, {0, 0, 0})));
    times.push_back(i);
  }
  std::vector<double> frames;
  for (int f = 0; f <= 30; ++f) frames.push_back(f / 10.0);
  for (auto method : {InterpolationMethod::Linear, InterpolationMethod::Approximating, InterpolationMethod::Subdivision}) {
    const auto r = interpolate_cameras(method, times, keys, frames);
    ASSERT_TRUE(r) << r.error().message;
    for (const Mat4& c : r.value()) EXPECT_LT(project(c, Eigen::Vector3d::Zero()).norm(), 0.05);
  }
}

TEST(CameraInterpolation, RefusesAHalfTurnBetweenKeys) {
  const std::vector<CameraKey> keys{camera_key(camera({0, 0, 5}, {0, 0, 0})), camera_key(camera({0, 0, -5}, {0, 0, 0}))};
  const std::vector<double> times{0, 1}, frames{0, 0.5, 1};
  const auto r = interpolate_cameras(InterpolationMethod::Linear, times, keys, frames);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, MatrixErrorCode::UnsafeStep);
  EXPECT_EQ(r.error().key, 1);
}

}  // namespace
}  // namespace posefair
