#include "posefair/core/repeated_exp.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace posefair {
namespace {

TEST(RepeatedExp, IsTheExponentialOfEachNewArgument) {
  RepeatedExp e;
  for (double x : {-0.001, -0.0011, 0.5, -50.0, 0.0, 1e-300, -2.5e-4, 2.5e-4})
    EXPECT_EQ(e(x), std::exp(x)) << x;
}

TEST(RepeatedExp, ReusesItsValueForAnArgumentWithinRoundingOfTheLast) {
  RepeatedExp e;
  const double dt = 0.001, tau = 0.1;
  const double first = e(-dt / tau);
  // A stream's next step as its time stamps round it: the value kept, within 1e-11 of exact.
  const double next = -(12346 * dt - 12345 * dt) / tau;
  ASSERT_NE(next, -dt / tau);
  EXPECT_EQ(e(next), first);
  EXPECT_NEAR(e(next), std::exp(next), 1e-11 * std::exp(next));
  // A step one per cent longer is new.
  EXPECT_EQ(e(-1.01 * dt / tau), std::exp(-1.01 * dt / tau));
}

TEST(RepeatedExp, ANotANumberIsNeverReused) {
  RepeatedExp e;
  EXPECT_TRUE(std::isnan(e(NAN)));
  EXPECT_EQ(e(-0.01), std::exp(-0.01));
  EXPECT_TRUE(std::isnan(e(NAN)));
}

}  // namespace
}  // namespace posefair
