#include "posefair/core/so3.hpp"

#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "test_sequences.hpp"

namespace posefair {
namespace {

using testing::random_direction;
using testing::random_unit_quaternion;
constexpr double kPi = std::numbers::pi;

// Half-angles covering the whole valid range of log, with the numerically hard ends.
const double kAngles[] = {0.0, 1e-300, 1e-200, 1e-16, 1e-12, 1e-9, 1e-8, 1e-6, 1e-5, 9.99e-5, 1e-4, 1.01e-4,
                          1e-3, 0.01, 0.1, 0.5, 1.0, 1.5, kPi / 2 - 1e-6, kPi / 2 - 1e-9, kPi / 2 - 1e-12, kPi / 2};

TEST(So3, ExpHasUnitNormAndHalfAngleConvention) {
  std::mt19937_64 rng(3);
  for (double a : kAngles) {
    const Vec3 axis = random_direction(rng);
    const Quat q = so3::exp(a * axis);
    ASSERT_FALSE(std::isnan(q.w()) || q.vec().hasNaN()) << a;
    EXPECT_NEAR(q.norm(), 1.0, 1e-15) << a;
    EXPECT_NEAR(q.w(), std::cos(a), 1e-15) << a;
    // The rotation angle of exp(v) is 2|v|: compare with Eigen's axis-angle.
    const Eigen::AngleAxisd ref(2.0 * a, axis);
    EXPECT_LT(so3::dist(q, Quat(ref)), 1e-14) << a;
  }
}

TEST(So3, LogInvertsExpOverTheWholeRange) {
  std::mt19937_64 rng(5);
  for (double a : kAngles) {
    for (int rep = 0; rep < 20; ++rep) {
      const Vec3 v = a * random_direction(rng);
      const Vec3 back = so3::log(so3::exp(v));
      ASSERT_FALSE(back.hasNaN()) << a;
      if (a < kPi / 2 - 1e-6) {
        EXPECT_LE((back - v).norm(), 1e-15 + 1e-14 * a) << "angle " << a;
      } else {
        // At |v| = pi/2 the hemisphere choice is ambiguous: v and -v are the same rotation.
        EXPECT_LT(so3::dist(so3::exp(back), so3::exp(v)), 1e-12) << a;
      }
    }
  }
}

TEST(So3, ExpInvertsLogForEveryUnitQuaternion) {
  std::mt19937_64 rng(7);
  for (int rep = 0; rep < 2000; ++rep) {
    Quat q = random_unit_quaternion(rng);
    const Vec3 v = so3::log(q);
    EXPECT_LE(v.norm(), kPi / 2 + 1e-15);
    const Quat back = so3::exp(v);
    EXPECT_LT(so3::dist(back, q), 1e-15);
    EXPECT_LT((back.coeffs() - so3::aligned_to(q, back).coeffs()).norm(), 1e-15);
  }
  // Near identity, near pi (w -> 0) and both hemispheres.
  for (double a : kAngles) {
    const Vec3 axis = random_direction(rng);
    for (double sign : {1.0, -1.0}) {
      const Quat q(sign * std::cos(a), sign * std::sin(a) * axis.x(), sign * std::sin(a) * axis.y(),
                   sign * std::sin(a) * axis.z());
      EXPECT_LT(so3::dist(so3::exp(so3::log(q)), q), 1e-15) << a;
    }
  }
}

TEST(So3, LogIgnoresNormAndSign) {
  const Quat q = so3::exp(Vec3(0.3, -0.2, 0.1));
  const Vec3 v = so3::log(q);
  EXPECT_LT((so3::log(Quat(-q.coeffs())) - v).norm(), 1e-15);
  EXPECT_LT((so3::log(Quat(3.0 * q.coeffs())) - v).norm(), 1e-15);
}

TEST(So3, DistIsAccurateAtTinyAnglesAndAtTheFarEnd) {
  std::mt19937_64 rng(11);
  for (double a : {1e-12, 1e-9, 1e-7, 1e-4, 0.3, 1.2, kPi / 2 - 1e-9}) {
    const Quat q = random_unit_quaternion(rng);
    const Quat r = q * so3::exp(a * random_direction(rng));
    EXPECT_NEAR(so3::dist(q, r), a, 1e-15 + a * 1e-9) << a;
    EXPECT_NEAR(so3::dist(q, Quat(-r.coeffs())), a, 1e-15 + a * 1e-9) << "antipode " << a;
    EXPECT_NEAR(so3::rotation_angle(q, r), 2 * a, 2e-15 + a * 2e-9) << a;
  }
}

TEST(So3, SlerpFollowsTheShorterArc) {
  const Quat a = so3::exp(Vec3(0.1, 0.2, 0.0));
  const Quat b = so3::exp(Vec3(0.4, -0.1, 0.3));
  EXPECT_LT(so3::dist(so3::slerp(0.0, a, b), a), 1e-15);
  EXPECT_LT(so3::dist(so3::slerp(1.0, a, b), b), 1e-15);
  const Quat mid = so3::slerp(0.5, a, b);
  EXPECT_NEAR(so3::dist(a, mid), so3::dist(a, b) / 2, 1e-15);
  EXPECT_NEAR(so3::dist(mid, b), so3::dist(a, b) / 2, 1e-15);
  // -b is the same rotation: the path must be the same, not the long way round.
  const Quat mid_flipped = so3::slerp(0.5, a, Quat(-b.coeffs()));
  EXPECT_LT(so3::dist(mid_flipped, mid), 1e-15);
}

TEST(So3, RotationVectorConversionUsesThePhysicalAngle) {
  const Vec3 r(0.0, 0.0, kPi / 2);  // 90 degrees about z
  const Quat q = so3::from_rotation_vector(r);
  const Vec3 x_rotated = q * Vec3::UnitX();
  EXPECT_LT((x_rotated - Vec3::UnitY()).norm(), 1e-15);
  EXPECT_LT((so3::to_rotation_vector(q) - r).norm(), 1e-15);
}

TEST(So3, MakeContinuousRemovesHemisphereFlipsWhateverTheInputSigns) {
  std::vector<Quat> base;
  for (int i = 0; i < 50; ++i) base.push_back(so3::exp(Vec3(0.05 * i, 0.02 * i, -0.03 * i)));
  std::vector<Quat> flipped = base;
  for (std::size_t i = 0; i < flipped.size(); i += 3) flipped[i].coeffs() = -flipped[i].coeffs();
  flipped[0].coeffs() = -flipped[0].coeffs();
  so3::make_continuous(base);
  so3::make_continuous(flipped);
  EXPECT_GE(base[0].w(), 0.0);
  for (std::size_t i = 0; i < base.size(); ++i) {
    EXPECT_EQ(base[i].coeffs(), flipped[i].coeffs()) << i;
    if (i > 0) {
      EXPECT_GE(base[i].dot(base[i - 1]), 0.0) << i;
    }
  }
}

}  // namespace
}  // namespace posefair
