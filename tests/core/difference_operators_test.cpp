#include "posefair/core/difference_operators.hpp"

#include <stdexcept>

#include <gtest/gtest.h>

#include "test_sequences.hpp"

namespace posefair {
namespace {

TEST(DifferenceOperators, PositionDifferencesOfPolynomials) {
  // p(i) = c i³: D³ p = 6c everywhere, D⁴ p = 0; valid range i = 0 … n-1-m.
  std::vector<Vec3> p;
  const Vec3 c(1.0, -2.0, 0.5);
  for (int i = 0; i < 10; ++i) p.push_back(c * static_cast<double>(i * i * i));
  const auto d3 = position_differences(p, 3);
  ASSERT_EQ(d3.size(), 7u);
  for (const Vec3& d : d3) EXPECT_LT((d - 6.0 * c).norm(), 1e-12);
  for (const Vec3& d : position_differences(p, 4)) EXPECT_LT(d.norm(), 1e-12);
  EXPECT_NEAR(translational_energy(p, 3), 7 * 36 * c.squaredNorm(), 1e-9);
  EXPECT_EQ(translational_energy(p, 4), 0.0);
}

TEST(DifferenceOperators, W1IsTheLogOfTheRelativeRotation) {
  const Quat q0 = so3::exp(Vec3(0.2, 0.1, -0.3));
  const Vec3 step(0.01, 0.02, 0.03);
  const auto q = testing::sequence_with_linear_w1(6, q0, step, Vec3::Zero());
  const auto w1 = orientation_differences(q, 1);
  ASSERT_EQ(w1.size(), 5u);
  for (const Vec3& w : w1) EXPECT_LT((w - step).norm(), 1e-14);
}

TEST(DifferenceOperators, ConstantAngularVelocityHasNoSecondOrderEnergy) {
  const auto q = testing::sequence_with_linear_w1(30, so3::exp(Vec3(0.5, 0.0, 0.2)), Vec3(0.03, -0.01, 0.02), Vec3::Zero());
  EXPECT_LT(rotational_energy(q, 2), 1e-26);
  EXPECT_LT(rotational_energy(q, 3), 1e-26);
}

TEST(DifferenceOperators, ConstantAngularAccelerationHasNoThirdOrderEnergy) {
  const auto q = testing::sequence_with_linear_w1(30, so3::exp(Vec3(0.5, 0.0, 0.2)), Vec3(0.03, -0.01, 0.02),
                                                  Vec3(0.001, 0.002, -0.001));
  EXPECT_GT(rotational_energy(q, 2), 1e-6);
  EXPECT_LT(rotational_energy(q, 3), 1e-26);
}

TEST(DifferenceOperators, W2HasTheSignOfEquationTen) {
  // Speeding up about z: W² q_i = log(q_{i+1}⁻¹ q_{i+2}) − log(q_i⁻¹ q_{i+1}) points along +z.
  // (Eq. 15 as printed would give −z; ERRATA item 1.)
  const auto q = testing::sequence_with_linear_w1(4, Quat::Identity(), Vec3(0, 0, 0.1), Vec3(0, 0, 0.05));
  const auto w2 = orientation_differences(q, 2);
  ASSERT_EQ(w2.size(), 2u);
  EXPECT_NEAR(w2[0].z(), 0.05, 1e-14);
  EXPECT_NEAR(w2[1].z(), 0.05, 1e-14);
}

TEST(DifferenceOperators, HemisphereFlipsChangeNothing) {
  auto q = testing::sequence_with_linear_w1(12, so3::exp(Vec3(0.5, 0.4, 0.2)), Vec3(0.1, -0.1, 0.05), Vec3(0.01, 0, 0));
  const auto ref = orientation_differences(q, 2);
  q[3].coeffs() = -q[3].coeffs();
  q[7].coeffs() = -q[7].coeffs();
  const auto flipped = orientation_differences(q, 2);
  for (std::size_t i = 0; i < ref.size(); ++i) EXPECT_LT((ref[i] - flipped[i]).norm(), 1e-15);
}

TEST(DifferenceOperators, TooShortOrBadOrderIsAnError) {
  const std::vector<Vec3> p(3, Vec3::Zero());
  const std::vector<Quat> q(3, Quat::Identity());
  EXPECT_THROW(position_differences(p, 3), std::invalid_argument);
  EXPECT_THROW(orientation_differences(q, 3), std::invalid_argument);
  EXPECT_THROW(position_differences(p, 0), std::invalid_argument);
  EXPECT_NO_THROW(orientation_differences(q, 2));
}

}  // namespace
}  // namespace posefair
