// Euler angles (BVH convention, degrees, R = R_first · R_second · R_third) <-> quaternions.
#include "posefair/core/euler_angles.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

namespace posefair {
namespace {

using Mat3 = Eigen::Matrix3d;

// Elementary rotations written out by hand (not via Eigen::AngleAxis, which the code uses).
Mat3 rx(double deg) {
  const double a = deg * std::numbers::pi / 180.0, c = std::cos(a), s = std::sin(a);
  Mat3 m;
  m << 1, 0, 0, 0, c, -s, 0, s, c;
  return m;
}
Mat3 ry(double deg) {
  const double a = deg * std::numbers::pi / 180.0, c = std::cos(a), s = std::sin(a);
  Mat3 m;
  m << c, 0, s, 0, 1, 0, -s, 0, c;
  return m;
}
Mat3 rz(double deg) {
  const double a = deg * std::numbers::pi / 180.0, c = std::cos(a), s = std::sin(a);
  Mat3 m;
  m << c, -s, 0, s, c, 0, 0, 0, 1;
  return m;
}
Mat3 elementary(Axis axis, double deg) {
  switch (axis) {
    case Axis::X: return rx(deg);
    case Axis::Y: return ry(deg);
    case Axis::Z: return rz(deg);
  }
  return Mat3::Identity();
}

const std::array<std::array<Axis, 3>, 6> kOrders = {{{Axis::X, Axis::Y, Axis::Z},
                                                     {Axis::X, Axis::Z, Axis::Y},
                                                     {Axis::Y, Axis::X, Axis::Z},
                                                     {Axis::Y, Axis::Z, Axis::X},
                                                     {Axis::Z, Axis::X, Axis::Y},
                                                     {Axis::Z, Axis::Y, Axis::X}}};

TEST(EulerAngles, ComposesInChannelOrderLikeHandWrittenMatrices) {
  const std::array<double, 3> deg = {-3.2316, -7.5970, -2.0168};
  for (const auto& order : kOrders) {
    const Mat3 expected = elementary(order[0], deg[0]) * elementary(order[1], deg[1]) *
                          elementary(order[2], deg[2]);
    const Quat q = euler_to_quat(order, deg);
    EXPECT_NEAR(q.norm(), 1.0, 1e-15);
    EXPECT_LT((q.toRotationMatrix() - expected).cwiseAbs().maxCoeff(), 1e-15);
  }
}

TEST(EulerAngles, SingleAxisIsTheElementaryRotation) {
  const std::array<Axis, 1> axes = {Axis::Y};
  const std::array<double, 1> deg = {90.0};
  const Quat q = euler_to_quat(axes, deg);
  EXPECT_NEAR(q.w(), std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(q.y(), std::sqrt(0.5), 1e-15);
  EXPECT_EQ(q.x(), 0.0);
  EXPECT_EQ(q.z(), 0.0);
  EXPECT_EQ(axis_from_char('z'), Axis::Z);
  EXPECT_FALSE(axis_from_char('w').has_value());
}

TEST(EulerAngles, InverseReproducesAnglesForEveryOrder) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> outer(-179.0, 179.0), middle(-89.0, 89.0);
  for (const auto& order : kOrders) {
    for (int n = 0; n < 200; ++n) {
      const std::array<double, 3> deg = {outer(rng), middle(rng), outer(rng)};
      const auto back = quat_to_euler_nearest(euler_to_quat(order, deg), order, deg);
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(back[i], deg[i], 1e-9);
    }
  }
}

TEST(EulerAngles, PicksTheSecondSolutionAndUnwrapsTowardTheReference) {
  // Middle angle beyond 90 and outer angles beyond 180: the principal solution differs, the
  // nearest equivalent solution is the input itself.
  const std::array<Axis, 3> order = {Axis::Z, Axis::X, Axis::Y};
  const std::array<double, 3> deg = {190.0, -100.0, 370.0};
  const Quat q = euler_to_quat(order, deg);
  const auto back = quat_to_euler_nearest(q, order, deg);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(back[i], deg[i], 1e-9);
  // With a reference near the principal solution, it is chosen instead: same rotation.
  const auto principal = quat_to_euler_nearest(q, order, {0.0, 0.0, 0.0});
  EXPECT_NEAR(principal[0], 10.0, 1e-9);
  EXPECT_NEAR(principal[1], -80.0, 1e-9);
  EXPECT_NEAR(principal[2], -170.0, 1e-9);
  EXPECT_LT(so3::rotation_angle(euler_to_quat(order, principal), q), 1e-12);
}

TEST(EulerAngles, SignOfTheQuaternionDoesNotMatter) {
  const std::array<Axis, 3> order = {Axis::Z, Axis::Y, Axis::X};
  const std::array<double, 3> deg = {33.0, -12.5, 140.0};
  const Quat q = euler_to_quat(order, deg);
  const auto back = quat_to_euler_nearest(Quat(-q.coeffs()), order, deg);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(back[i], deg[i], 1e-9);
}

TEST(EulerAngles, GimbalLockKeepsTheReferenceSplit) {
  // Middle angle exactly 90: only a combination of the outer angles is defined.
  for (const auto& order : kOrders) {
    for (const double middle : {90.0, -90.0, 89.9999999}) {
      const std::array<double, 3> deg = {-6.5, middle, 13.25};
      const Quat q = euler_to_quat(order, deg);
      const auto back = quat_to_euler_nearest(q, order, deg);
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(back[i], deg[i], 1e-9) << "middle " << middle;
      // A reference that does not match still gives the same rotation.
      const auto other = quat_to_euler_nearest(q, order, {50.0, 0.0, 0.0});
      EXPECT_LT(so3::rotation_angle(euler_to_quat(order, other), q), 1e-12);
    }
  }
}

TEST(EulerAngles, ChangedRotationIsExactAndNearTheReference) {
  const std::array<Axis, 3> order = {Axis::Z, Axis::Y, Axis::X};
  const std::array<double, 3> deg = {170.0, 20.0, -175.0};
  const Quat q = euler_to_quat(order, deg) * so3::from_rotation_vector(Vec3(0.01, -0.02, 0.015));
  const auto back = quat_to_euler_nearest(q, order, deg);
  EXPECT_LT(so3::rotation_angle(euler_to_quat(order, back), q), 1e-13);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(back[i], deg[i], 3.0);  // no jump by 360 or to the other solution
}

TEST(EulerAngles, RejectsRepeatedAxes) {
  EXPECT_THROW(quat_to_euler_nearest(Quat::Identity(), {Axis::Z, Axis::X, Axis::Z}, {0, 0, 0}),
               std::invalid_argument);
}

}  // namespace
}  // namespace posefair
