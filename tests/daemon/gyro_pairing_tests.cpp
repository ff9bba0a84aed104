// [stream.engine] gyro_stream's matcher (daemon/…/gyro_pairing.hpp): each orientation sample
// gets the source's rate at its own time from the readings of its interval, exactly for a rate
// that changes linearly whatever the spacing of either stream; no reading in the interval is no
// match; readings past the sample wait for the next interval; bad readings are left out; a gap
// is not averaged over.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "posefair/daemon/gyro_pairing.hpp"

namespace posefair::daemon {
namespace {

Vec3 linear_rate(double t) { return Vec3(0.5 + 2.0 * t, -1.0 + 0.3 * t, 4.0 * t); }

Sample orientation_at(double t) {
  Sample s;
  s.time = t;
  return s;
}

TEST(GyroPairing, ALinearlyChangingRateIsMatchedExactlyAtEachSamplesTime) {
  GyroPairing pairing;
  // An IMU at about 1 kHz with uneven spacing, a tracker at about 120 Hz with jitter.
  double next_reading = 0.0;
  int matched = 0;
  for (int k = 0; k < 60; ++k) {
    const double t = k / 120.0 + ((k % 3) - 1) * 0.0007;
    for (; next_reading <= t; next_reading += 0.001 + 0.0003 * std::sin(next_reading * 977.0))
      pairing.add(next_reading, linear_rate(next_reading));
    Sample s = orientation_at(t);
    pairing.apply(s);
    if (k == 0) {
      EXPECT_FALSE(s.has_gyro()) << "the first sample has no interval";
      continue;
    }
    ASSERT_TRUE(s.has_gyro()) << k;
    if (k >= 2) {  // the line needs the previous interval's mean
      EXPECT_LT((s.gyro - linear_rate(t)).norm(), 1e-9) << k;
      ++matched;
    }
  }
  EXPECT_EQ(matched, 58);
  EXPECT_EQ(pairing.matched(), 59u);
  EXPECT_EQ(pairing.unmatched(), 1u);
}

TEST(GyroPairing, WithoutAReadingInItsIntervalASampleLosesItsGyro) {
  GyroPairing pairing;
  pairing.add(0.001, Vec3(1, 2, 3));
  Sample first = orientation_at(0.002);
  pairing.apply(first);
  Sample s = orientation_at(0.010);
  s.gyro = Vec3(9, 9, 9);  // its own reading is never mixed with the source's
  s.flags = kHasGyro;
  pairing.apply(s);
  EXPECT_FALSE(s.has_gyro());
  EXPECT_EQ(pairing.unmatched(), 2u);
  pairing.add(0.015, Vec3(1, 1, 1));
  Sample next = orientation_at(0.020);
  pairing.apply(next);
  ASSERT_TRUE(next.has_gyro());
  EXPECT_EQ(next.gyro, Vec3(1, 1, 1)) << "after an unmatched interval there is no line: the mean";
  EXPECT_EQ(pairing.matched(), 1u);
}

TEST(GyroPairing, ReadingsPastTheSampleWaitForTheNextInterval) {
  GyroPairing pairing;
  Sample first = orientation_at(0.0);
  pairing.apply(first);
  for (int i = 1; i <= 20; ++i) pairing.add(0.001 * i, Vec3(i <= 10 ? 1.0 : 5.0, 0, 0));  // the source is ahead
  Sample s = orientation_at(0.010);
  pairing.apply(s);
  ASSERT_TRUE(s.has_gyro());
  EXPECT_DOUBLE_EQ(s.gyro.x(), 1.0);
  Sample later = orientation_at(0.020);
  pairing.apply(later);
  ASSERT_TRUE(later.has_gyro());
  // The mean of (0.010, 0.020] is 5 at 0.0155, the previous interval's 1 at 0.0055: carried
  // to 0.020 along the line through them, 5 + 4 · 0.0045 / 0.01.
  EXPECT_NEAR(later.gyro.x(), 5.0 + 4.0 * 0.45, 1e-12);
}

TEST(GyroPairing, NonFiniteAndOutOfOrderReadingsAndRepeatedSamplesAreLeftOut) {
  GyroPairing pairing;
  Sample first = orientation_at(0.0);
  pairing.apply(first);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  pairing.add(0.002, Vec3(2, 0, 0));
  pairing.add(0.003, Vec3(nan, 0, 0));
  pairing.add(0.001, Vec3(100, 0, 0));  // older than the newest kept
  pairing.add(nan, Vec3(100, 0, 0));
  pairing.add(0.004, Vec3(4, 0, 0));
  Sample s = orientation_at(0.005);
  pairing.apply(s);
  ASSERT_TRUE(s.has_gyro());
  EXPECT_DOUBLE_EQ(s.gyro.x(), 3.0);
  Sample repeated = orientation_at(0.005);  // the engine's gate drops it: no interval, not counted
  pairing.apply(repeated);
  EXPECT_FALSE(repeated.has_gyro());
  EXPECT_EQ(pairing.matched() + pairing.unmatched(), 2u);
}

TEST(GyroPairing, AfterAGapOnlyTheLastIntervalOfTheOldLengthIsAveraged) {
  GyroPairing pairing;
  for (int i = 1; i <= 100; ++i) pairing.add(0.001 * i, Vec3(i < 90 ? 9.0 : 1.0, 0, 0));
  for (double t : {0.0, 0.010}) {
    Sample s = orientation_at(t);
    pairing.apply(s);
  }
  Sample after_gap = orientation_at(0.100);  // 90 ms after the last sample, whose interval was 10 ms
  pairing.apply(after_gap);
  ASSERT_TRUE(after_gap.has_gyro());
  EXPECT_DOUBLE_EQ(after_gap.gyro.x(), 1.0) << "the readings of (0.090, 0.100] alone, and no line through the old mean";
}

TEST(GyroPairing, OnlyTheNewestReadingsAreKept) {
  GyroPairing pairing;
  Sample first = orientation_at(0.0);
  pairing.apply(first);
  const std::size_t n = 3 * GyroPairing::kCapacity;
  for (std::size_t i = 1; i <= n; ++i) pairing.add(1e-4 * static_cast<double>(i), Vec3(i > n - GyroPairing::kCapacity ? 1.0 : 7.0, 0, 0));
  Sample s = orientation_at(1.0);
  pairing.apply(s);
  ASSERT_TRUE(s.has_gyro());
  EXPECT_DOUBLE_EQ(s.gyro.x(), 1.0) << "the older readings were overwritten";
}

}  // namespace
}  // namespace posefair::daemon
